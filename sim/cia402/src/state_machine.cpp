// The simulated drive's power state machine (CiA 402 figure 5), driven by the controlword.
#include "drive_state.hpp"

namespace pathstream::sim {

using namespace host::cia402;

void SimulatedCia402Drive::State::apply_controlword(std::uint16_t cw) {
    const bool reset_edge = (cw & 0x80) != 0 && (controlword & 0x80) == 0;
    controlword = cw;
    if (ds == DriveState::kFault || ds == DriveState::kFaultReactionActive) {
        // Only a fault reset leaves fault (transition 15), on the rising edge of bit 7.
        if (ds == DriveState::kFault && reset_edge) {
            ds = DriveState::kSwitchOnDisabled;
            error_code = 0;
            emcy(kEmcyNoError);  // "error reset": the EMCY producer's way to say it is clear
        }
        return;
    }
    const bool enable_voltage = (cw & 0x02) != 0;
    const bool no_quick_stop = (cw & 0x04) != 0;
    const bool switch_on = (cw & 0x01) != 0;
    const bool enable_operation = (cw & 0x08) != 0;
    const auto enter_enabled = [&] {
        ds = DriveState::kOperationEnabled;
        demand = position;  // CSP starts from where the axis is; the next target moves it
        last_step = 0;
    };
    if (!enable_voltage) {  // disable voltage (transitions 7, 9, 10, 12)
        if (ds != DriveState::kNotReadyToSwitchOn) ds = DriveState::kSwitchOnDisabled;
        return;
    }
    if (!no_quick_stop) {  // quick stop (transitions 7, 10, 11)
        if (ds == DriveState::kOperationEnabled) {
            ds = DriveState::kQuickStopActive;
        } else if (ds == DriveState::kReadyToSwitchOn || ds == DriveState::kSwitchedOn) {
            ds = DriveState::kSwitchOnDisabled;
        }
        return;
    }
    if (!switch_on) {  // shutdown (transitions 2, 6, 8)
        if (ds == DriveState::kSwitchOnDisabled || ds == DriveState::kSwitchedOn ||
            ds == DriveState::kOperationEnabled) {
            ds = DriveState::kReadyToSwitchOn;
        }
        return;
    }
    if (!enable_operation) {  // switch on (3) or disable operation (5)
        if (ds == DriveState::kReadyToSwitchOn || ds == DriveState::kOperationEnabled)
            ds = DriveState::kSwitchedOn;
        return;
    }
    // enable operation (4); a quick stop active drive stays there until disabled (option 2)
    if (ds == DriveState::kSwitchedOn) enter_enabled();
}

}  // namespace pathstream::sim
