// pathstream_pty_fault_proxy: a faulty serial line between two ptys, for trying RTU masters
// and servers by hand (tests use the PtyFaultProxy class directly).
//   pathstream_pty_fault_proxy [--corrupt-rate R] [--drop-rate R] [--seed N]
// Prints "A /dev/pts/X" and "B /dev/pts/Y", then forwards until SIGINT/SIGTERM and prints
// the counters on stderr.
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "pathstream/sim/pty_fault_proxy.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) {
    g_stop = 1;
}

int usage() {
    std::fprintf(
        stderr,
        "usage: pathstream_pty_fault_proxy [--corrupt-rate R] [--drop-rate R] [--seed N]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    pathstream::sim::PtyFaultOptions options;
    try {
        for (int i = 1; i < argc; ++i) {
            const std::string arg = argv[i];
            if (i + 1 >= argc) return usage();
            const std::string value = argv[++i];
            std::size_t used = 0;
            if (arg == "--corrupt-rate") {
                options.corrupt_rate = std::stod(value, &used);
            } else if (arg == "--drop-rate") {
                options.drop_rate = std::stod(value, &used);
            } else if (arg == "--seed") {
                options.seed = std::stoull(value, &used);
            } else {
                return usage();
            }
            if (used != value.size()) return usage();
        }
        pathstream::sim::PtyFaultProxy proxy(options);
        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        std::printf("A %s\nB %s\n", proxy.path_a().c_str(), proxy.path_b().c_str());
        std::fflush(stdout);
        while (g_stop == 0) proxy.poll_once(std::chrono::milliseconds(100));
        const auto& c = proxy.counters();
        std::fprintf(
            stderr,
            "a->b %llu bytes, b->a %llu bytes, corrupted %llu, dropped %llu, overflowed %llu\n",
            static_cast<unsigned long long>(c.bytes_a_to_b.load()),
            static_cast<unsigned long long>(c.bytes_b_to_a.load()),
            static_cast<unsigned long long>(c.corrupted.load()),
            static_cast<unsigned long long>(c.dropped.load()),
            static_cast<unsigned long long>(c.overflowed.load()));
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "pathstream_pty_fault_proxy: %s\n", e.what());
        return usage();
    }
}
