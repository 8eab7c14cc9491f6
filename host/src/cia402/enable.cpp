// The CiA 402 power state machine from the master's side: shutdown -> switch on -> enable
// operation, one command per cycle chosen from each drive's last statusword; fault reset.
#include <string>

#include "pathstream/host/cia402_master.hpp"

namespace pathstream::host {

using namespace cia402;

namespace {

// The controlword that moves a drive in `state` one step towards operation enabled.
std::uint16_t towards_enabled(DriveState state) {
    switch (state) {
        case DriveState::kSwitchOnDisabled:
            return kCwShutdown;
        case DriveState::kReadyToSwitchOn:
            return kCwSwitchOn;
        case DriveState::kSwitchedOn:
        case DriveState::kOperationEnabled:
            return kCwEnableOperation;
        case DriveState::kQuickStopActive:
            return kCwDisableVoltage;  // back to switch on disabled
        default:
            return kCwShutdown;  // not ready yet (or no feedback): a harmless command
    }
}

}  // namespace

Cia402Stop Cia402Master::enable(const std::vector<std::int32_t>& targets) {
    const std::uint64_t deadline = clock_.now() + std::uint64_t{options_.enable_timeout_ms} * 1000;
    std::vector<std::uint16_t> cws(drives_.size(), kCwShutdown);
    for (;;) {
        exchange(cws, targets);
        if (const Cia402Stop s = check_health(false); s != Cia402Stop::kNone) return s;
        bool all = true;
        for (std::size_t i = 0; i < drives_.size(); ++i) {
            const DriveState s = drives_[i].state();
            all = all && drives_[i].feedback_cycle == cycle_ && s == DriveState::kOperationEnabled;
            cws[i] = towards_enabled(s);
        }
        if (all) return Cia402Stop::kNone;
        if (clock_.now() >= deadline) {
            for (const auto& d : drives_) {
                if (d.state() != DriveState::kOperationEnabled) {
                    return stop_with(Cia402Stop::kDriveLeftOperation,
                                     "node " + std::to_string(d.node) +
                                         ": not operation enabled after " +
                                         std::to_string(options_.enable_timeout_ms) +
                                         " ms (still " + drive_state_name(d.state()) + ")");
                }
            }
        }
    }
}

bool Cia402Master::fault_reset() {
    // Fault reset acts on the rising edge of bit 7: one cycle with it clear, then set.
    std::vector<std::int32_t> hold;
    for (const auto& d : drives_) hold.push_back(d.position);
    exchange(std::vector<std::uint16_t>(drives_.size(), kCwDisableVoltage), hold);
    const std::uint64_t deadline = clock_.now() + std::uint64_t{options_.enable_timeout_ms} * 1000;
    const std::vector<std::uint16_t> reset(drives_.size(), kCwFaultReset);
    while (clock_.now() < deadline) {
        exchange(reset, hold);
        bool clear = true;
        for (const auto& d : drives_) {
            const DriveState s = d.state();
            clear = clear && d.feedback_cycle == cycle_ && s != DriveState::kFault &&
                    s != DriveState::kFaultReactionActive;
        }
        if (clear) {
            for (auto& d : drives_) {
                d.emcy_pending = false;
                d.emcy_code = 0;
            }
            report_.stop = Cia402Stop::kNone;
            report_.message.clear();
            return true;
        }
    }
    return false;
}

}  // namespace pathstream::host
