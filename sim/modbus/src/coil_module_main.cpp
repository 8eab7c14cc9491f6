// pathstream_coil_module: a simulated Modbus TCP I/O module with coils (sim::CoilModule), for
// scripts that run `pathstream device` with a profile's "output_coils".
//   pathstream_coil_module [--coils N] [--port P] [--seconds S]
// Prints "port N" once it listens, then one line per coil change ("coil 0 on", "coil 3 off"),
// each flushed, until SIGINT/SIGTERM or S seconds (default 60: a forgotten module never
// outlives its test), then "write requests N" (FC5 and FC15 answered, refused ones included). Exits
// 0; 2 for a bad command line, 1 when it cannot listen.
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>
#include <thread>

#include "pathstream/sim/coil_module.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) {
    g_stop = 1;
}

int usage() {
    std::fprintf(stderr, "usage: pathstream_coil_module [--coils N] [--port P] [--seconds S]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    int coils = 16, port = 0, seconds = 60;
    if (argc % 2 != 1) return usage();
    try {
        for (int i = 1; i + 1 < argc; i += 2) {
            const std::string arg = argv[i];
            const int value = std::stoi(argv[i + 1]);
            if (arg == "--coils" && value >= 1 && value <= 65536) {
                coils = value;
            } else if (arg == "--port" && value >= 0 && value <= 65535) {
                port = value;
            } else if (arg == "--seconds" && value >= 1) {
                seconds = value;
            } else {
                return usage();
            }
        }
    } catch (const std::exception&) {
        return usage();
    }
    try {
        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        pathstream::sim::CoilModule module(static_cast<std::uint32_t>(coils),
                                           static_cast<std::uint16_t>(port));
        std::printf("port %u\n", static_cast<unsigned>(module.port()));
        std::fflush(stdout);
        std::size_t printed = 0;
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
        while (g_stop == 0 && std::chrono::steady_clock::now() < end) {
            const auto changes = module.changes();
            for (; printed < changes.size(); ++printed) {
                std::printf("coil %u %s\n", static_cast<unsigned>(changes[printed].coil),
                            changes[printed].on ? "on" : "off");
            }
            std::fflush(stdout);
            std::this_thread::sleep_for(std::chrono::milliseconds(5));
        }
        module.stop();
        const auto changes = module.changes();
        for (; printed < changes.size(); ++printed) {
            std::printf("coil %u %s\n", static_cast<unsigned>(changes[printed].coil),
                        changes[printed].on ? "on" : "off");
        }
        std::printf("write requests %llu\n",
                    static_cast<unsigned long long>(module.write_requests()));
        std::fflush(stdout);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "pathstream_coil_module: %s\n", e.what());
        return 1;
    }
}
