// The native CAN transport to one device.
#include "can_link.hpp"

#include <algorithm>
#include <stdexcept>

#include "pathstream/status.hpp"

namespace pathstream::host {

std::string can_result_name(std::uint8_t r) {
    switch (r) {
        case pc::kResultIncomplete:
            return "incomplete transfer";
        case pc::kResultBadFrame:
            return "bad frame";
        case pc::kResultTooLong:
            return "batch too long";
        default:
            return status_name(static_cast<Status>(r));
    }
}

DeviceSnapshot snapshot_of(const pc::Status3& s) {
    DeviceSnapshot d;
    d.version = s.version;
    d.axes = s.axes;
    d.state = device_state_of_wire(s.state);
    d.fault_code = s.fault_code;
    d.free_slots = s.free_slots;
    d.queued = s.queued;
    // Status A's flags agree with the snapshot's bits; its pen and spindle flags are the
    // snapshot's outputs (CAN reports no coolant).
    d.flags = s.flags & ~unsigned{pc::kFlagPenDown | pc::kFlagSpindle};
    d.outputs = ((s.flags & pc::kFlagPenDown) != 0 ? kOutputPenDown : 0u) |
                ((s.flags & pc::kFlagSpindle) != 0 ? kOutputSpindle : 0u);
    d.underruns = s.underruns;
    d.duplicates = s.duplicates;
    d.last_accepted = s.last_accepted;
    d.last_completed = s.last_completed;
    d.ticks_executed = s.ticks_executed;
    d.finished_job = s.finished_job;
    d.finished_job_ticks = s.finished_job_ticks;
    d.epoch = s.epoch;
    std::copy(s.position, s.position + kMaxAxes, d.position);
    for (unsigned a = 0; a < kMaxAxes; ++a) {
        d.homing[a].state = static_cast<device::AxisHoming>(s.homing[a] & 0x0Fu);
        d.homing[a].error = static_cast<device::HomingError>(s.homing[a] >> 4);
    }
    return d;
}

CanLink::CanLink(hal::CanBus& bus, const CanStreamOptions& options, CanStreamReport& counters)
    : bus_(bus), options_(options), node_(options.node), counters_(counters) {
    if (node_ < pc::kMinNode || node_ > pc::kMaxNode)
        throw std::invalid_argument("CAN node id outside 1..127");
}

}  // namespace pathstream::host
