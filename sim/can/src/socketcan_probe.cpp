// socketcan_probe IFACE: SocketCanBus on a real kernel (run in the VM on vcan0 by
// can.socketcan.vm): frames between two sockets, no echo to the sender, CAN_RAW_FILTER id/mask
// (standard and extended kept apart), counters, receive timeout. Prints "ok" or what failed.
#include <chrono>
#include <cstdio>
#include <string>

#include "pathstream/hal/socketcan_bus.hpp"

using namespace pathstream::hal;

namespace {

int failures = 0;
void expect(bool ok, const char* what) {
    if (!ok) {
        std::printf("FAIL: %s\n", what);
        ++failures;
    }
}

CanFrame frame(std::uint32_t id, bool extended, std::uint8_t length) {
    CanFrame f;
    f.id = id;
    f.extended = extended;
    f.length = length;
    for (std::uint8_t i = 0; i < length; ++i) f.data[i] = static_cast<std::uint8_t>(0xA0 + i);
    return f;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: socketcan_probe IFACE\n");
        return 2;
    }
    const std::string iface = argv[1];
    SocketCanBus a(iface);
    SocketCanBus b(iface,
                   {{0x400, 0x780, false}});  // 0x400..0x47F: span start frames of every node
    expect(a.send(frame(0x405, false, 8)) == CanSendResult::kQueued, "send 0x405");
    expect(a.send(frame(0x105, false, 1)) == CanSendResult::kQueued, "send 0x105");
    expect(a.send(frame(0x405, true, 2)) == CanSendResult::kQueued, "send extended 0x405");
    expect(a.send(frame(0x47F, false, 0)) == CanSendResult::kQueued, "send 0x47F");
    CanFrame f;
    expect(
        b.receive(f, 1000000) && f.id == 0x405 && !f.extended && f.length == 8 && f.data[7] == 0xA7,
        "b receives 0x405 with its data");
    expect(b.receive(f, 1000000) && f.id == 0x47F && f.length == 0,
           "b receives 0x47F (0x105 and extended 0x405 filtered)");
    expect(!b.receive(f, 50000), "b receives nothing more");
    expect(!a.receive(f, 50000), "a does not receive its own frames");
    expect(a.counters().frames_sent == 4 && b.counters().frames_received == 2, "counters");
    b.set_filters({});
    expect(a.send(frame(0x105, false, 1)) == CanSendResult::kQueued && b.receive(f, 1000000) &&
               f.id == 0x105,
           "no filters: everything passes");
    expect(a.send(frame(0x800, false, 1)) == CanSendResult::kError,
           "an 11-bit id above 0x7FF is refused");
    expect(a.state() == CanBusState::kErrorActive, "vcan stays error-active");
    const auto t0 = std::chrono::steady_clock::now();
    expect(!b.receive(f, 30000), "timeout");
    const double waited =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    expect(waited >= 0.029 && waited < 1.0, "the receive timeout is kept");
    std::printf(failures == 0 ? "ok\n" : "%d failures\n", failures);
    return failures == 0 ? 0 : 1;
}
