// The simulated CiA 402 drive's frame handling (SDO server, NMT, RPDO, SYNC) from a master on
// a loopback bus: any frames, time advancing between them. Every answer is a valid classic
// frame with an 11-bit id; an SDO request the drive aborts changes neither its state machine
// nor its mode of operation nor its interpolation period.
#include "device_fingerprint.hpp"
#include "fuzz_support.hpp"
#include "pathstream/machine/cia402_protocol.hpp"
#include "pathstream/sim/can_loopback.hpp"
#include "pathstream/sim/cia402_drive.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    namespace co = host::cia402;
    fuzz::Input in(data, size);
    sim::CanLoopback loopback;
    hal::CanBus& master = loopback.add_endpoint();
    hal::CanBus& drive_bus = loopback.add_endpoint();
    sim::Cia402DriveOptions options;
    options.node = 3;
    sim::SimulatedCia402Drive drive(drive_bus, options);
    std::uint64_t now_us = 0;
    drive.poll(now_us);
    hal::CanFrame answer;
    while (master.receive(answer, 0)) {
    }
    // NMT and SYNC as they are; SDO requests (twice as often) and RPDO 1..4 to node 3 or any.
    const std::uint32_t bases[] = {
        co::kNmtId, co::kSyncId, co::kSdoRequestBase, co::kRpdo1Base, 0x300,
        0x400,      0x500,       co::kSdoRequestBase};
    while (!in.done()) {
        const std::uint8_t how = in.byte();
        hal::CanFrame f;
        const bool broadcast = (how & 7u) < 2;
        f.id = broadcast ? bases[how & 7u]
                         : bases[how & 7u] + ((how & 8u) != 0 ? in.byte() & 0x7Fu : 3u);
        f.length = static_cast<std::uint8_t>(in.byte() % 9u);
        for (std::uint8_t& b : f.data) b = in.byte();
        const std::uint16_t status_before = drive.statusword();
        const std::int8_t mode_before = drive.mode();
        const std::uint32_t period_before = drive.interpolation_period_ms();
        (void)master.send(f);
        now_us += 100 * static_cast<std::uint64_t>(in.byte());
        drive.poll(now_us);
        bool aborted = false;
        while (master.receive(answer, 0)) {
            if (answer.length > 8 || answer.id > 0x7FF || answer.extended)
                fuzz::violated("an invalid answer frame");
            if (answer.id == co::kSdoResponseBase + 3 && answer.length == 8 &&
                answer.data[0] == 0x80)
                aborted = true;
        }
        if (aborted && (drive.statusword() != status_before || drive.mode() != mode_before ||
                        drive.interpolation_period_ms() != period_before)) {
            fuzz::violated("an aborted SDO request changed the drive");
        }
    }
    return 0;
}
