// pathstream_modbus_test_server: a ModbusServer over a fixed register pattern, for
// interoperability checks with independent masters (mbpoll, pymodbus).
//   pathstream_modbus_test_server tcp|rtu-pty|rtu [--device PATH] [--baud B] [--unit N] [--seconds
//   S]
// Input register a holds 1000 + a; holding registers start at 0 and accept any write.
// rtu serves an existing serial device (e.g. a PtyFaultProxy side) at B baud, 8N1.
// Prints "port N" (tcp) or "device PATH" (rtu, rtu-pty) once ready, then serves until
// SIGINT/SIGTERM or S seconds (default 30: a forgotten server never outlives its test).
#include <chrono>
#include <csignal>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "pathstream/hal/modbus_server.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) {
    g_stop = 1;
}

class PatternRegisters final : public pathstream::hal::ModbusRegisterHandler {
public:
    using Ex = pathstream::hal::ModbusException;
    Ex read_input_registers(std::uint16_t address, std::uint16_t count,
                            std::uint16_t* out) override {
        for (std::uint16_t i = 0; i < count; ++i)
            out[i] = static_cast<std::uint16_t>(1000 + address + i);
        return Ex::kNone;
    }
    Ex read_holding_registers(std::uint16_t address, std::uint16_t count,
                              std::uint16_t* out) override {
        for (std::uint16_t i = 0; i < count; ++i)
            out[i] = holding_[static_cast<std::size_t>(address) + i];
        return Ex::kNone;
    }
    Ex write_holding_registers(std::uint16_t address, std::uint16_t count,
                               const std::uint16_t* values) override {
        for (std::uint16_t i = 0; i < count; ++i)
            holding_[static_cast<std::size_t>(address) + i] = values[i];
        return Ex::kNone;
    }

private:
    std::vector<std::uint16_t> holding_ = std::vector<std::uint16_t>(65536);
};

int usage() {
    std::fprintf(stderr,
                 "usage: pathstream_modbus_test_server tcp|rtu-pty|rtu [--device PATH] [--baud B] "
                 "[--unit N] [--seconds S]\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) return usage();
    const std::string mode = argv[1];
    pathstream::hal::ModbusServerOptions options;
    int seconds = 30;
    pathstream::hal::ModbusSerialLine line;
    line.baud = 115200;
    line.parity = 'N';
    try {
        for (int i = 2; i + 1 < argc; i += 2) {
            const std::string arg = argv[i];
            if (arg == "--unit") {
                options.unit = std::stoi(argv[i + 1]);
            } else if (arg == "--device") {
                line.device = argv[i + 1];
            } else if (arg == "--baud") {
                line.baud = std::stoi(argv[i + 1]);
            } else if (arg == "--seconds") {
                seconds = std::stoi(argv[i + 1]);
            } else {
                return usage();
            }
        }
        if (argc % 2 != 0) return usage();  // an option without its value
        PatternRegisters registers;
        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        pathstream::hal::ModbusServer server =
            mode == "tcp"       ? pathstream::hal::ModbusServer::tcp(registers, {}, options)
            : mode == "rtu-pty" ? pathstream::hal::ModbusServer::rtu_pty(registers, options)
            : mode == "rtu"     ? pathstream::hal::ModbusServer::rtu(registers, line, options)
                                : throw std::invalid_argument("unknown mode '" + mode + "'");
        if (mode == "tcp") {
            std::printf("port %u\n", static_cast<unsigned>(server.port()));
        } else {
            std::printf("device %s\n", server.client_device().c_str());
        }
        std::fflush(stdout);
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(seconds);
        while (g_stop == 0 && std::chrono::steady_clock::now() < end) {
            server.poll_once(std::chrono::milliseconds(50));
        }
        const auto& c = server.counters();
        std::fprintf(stderr, "requests %llu, exceptions %llu, bad frames %llu\n",
                     static_cast<unsigned long long>(c.requests.load()),
                     static_cast<unsigned long long>(c.exceptions.load()),
                     static_cast<unsigned long long>(c.bad_frames.load()));
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "pathstream_modbus_test_server: %s\n", e.what());
        return 1;
    }
}
