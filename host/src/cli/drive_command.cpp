#include "drive_command.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <deque>
#include <iostream>

#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/host/cia402_master.hpp"
#include "pathstream/sim/cia402_drive.hpp"

namespace pathstream::host {
namespace {

std::atomic<bool> g_drive_stop{false};
extern "C" void on_drive_signal(int) {
    g_drive_stop.store(true);
}

// The drive polls its bus without waiting; this loop waits on the socket instead and hands
// the frame it woke up for to the drive first.
class WaitingBus final : public hal::CanBus {
public:
    explicit WaitingBus(hal::CanBus& inner) : inner_(inner) {}
    hal::CanSendResult send(const hal::CanFrame& f) override { return inner_.send(f); }
    bool receive(hal::CanFrame& out, std::uint32_t timeout_us) override {
        if (!pending_.empty()) {
            out = pending_.front();
            pending_.pop_front();
            return true;
        }
        return inner_.receive(out, timeout_us);
    }
    hal::CanBusState state() const override { return inner_.state(); }
    /// Waits up to `timeout_us` for a frame and keeps it for the drive.
    void wait(std::uint32_t timeout_us) {
        hal::CanFrame f;
        if (inner_.receive(f, timeout_us)) pending_.push_back(f);
    }

private:
    hal::CanBus& inner_;
    std::deque<hal::CanFrame> pending_;
};

}  // namespace

void add_drive_command(CLI::App& app, DriveCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "drive",
        "Run a simulated CiA 402 servo drive (CSP) on a SocketCAN interface (docs/cia402.md)");
    cmd->add_option("--can", o.can, "CAN interface, e.g. vcan0")->required();
    cmd->add_option("--node", o.node, "CANopen node id")
        ->capture_default_str()
        ->check(CLI::Range(1u, 127u));
    cmd->add_option("--position", o.position, "position at power-up, LSB")->capture_default_str();
    cmd->add_option("--bandwidth", o.bandwidth_hz, "servo plant natural frequency, Hz")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 10000.0));
    cmd->add_option("--following-window", o.following_window,
                    "following error window (0x6065), LSB")
        ->capture_default_str();
    cmd->add_option("--inertia", o.inertia,
                    "torque offset (0x60B2, per mille of rated torque) per LSB/s^2 of "
                    "acceleration; 0: the drive has no torque model and refuses to map 0x60B2")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 1e6));
    cmd->add_option("--exit-after", o.exit_after,
                    "stop after this many seconds (default: at SIGINT/SIGTERM)")
        ->check(CLI::Range(0.0, 1e6));
}

int run_drive(const DriveCommandOptions& o) {
    hal::SocketCanBus socket(o.can);
    WaitingBus bus(socket);
    sim::Cia402DriveOptions d;
    d.node = static_cast<std::uint8_t>(o.node);
    d.start_position = o.position;
    d.servo.bandwidth_hz = o.bandwidth_hz;
    d.following_error_window = o.following_window;
    d.torque_per_acceleration = o.inertia;
    sim::SimulatedCia402Drive drive(bus, d);
    std::signal(SIGINT, on_drive_signal);
    std::signal(SIGTERM, on_drive_signal);
    SteadyMicrosecondClock clock;
    std::cout << "pathstream drive: CiA 402 node " << o.node << " on " << o.can << " at "
              << o.position << " LSB" << std::endl;
    const std::uint64_t end =
        o.exit_after > 0 ? static_cast<std::uint64_t>(o.exit_after * 1e6) : UINT64_MAX;
    for (;;) {
        const std::uint64_t now = clock.now();
        if (g_drive_stop.load() || now >= end) break;
        drive.poll(now);
        // Wake for the next frame, the next heartbeat, or at least every 10 ms for the signals.
        const std::uint64_t next = std::min({drive.next_event_us(), end, clock.now() + 10000});
        const std::uint64_t t = clock.now();
        bus.wait(static_cast<std::uint32_t>(next > t ? next - t : 0));
    }
    std::cout << "pathstream drive: stopped in state " << cia402::drive_state_name(drive.state())
              << " at " << drive.position_actual() << " LSB; " << drive.syncs() << " SYNCs, "
              << drive.rpdos() << " RPDOs, " << drive.applied_targets().size()
              << " targets applied, max following error " << drive.max_following_error() << " LSB"
              << std::endl;
    return 0;
}

}  // namespace pathstream::host
