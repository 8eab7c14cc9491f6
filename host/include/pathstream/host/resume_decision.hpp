// What `stream --resume` does with a journaled job after a hold, a stop, a fault reset, a
// device restart or a host crash: one decision from the journal's last record and a read of
// the device's status, free of I/O, so that every case can be tested without a device. The
// command reads the status, waits, prints and acts; it asks again after each read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "pathstream/host/device_link.hpp"
#include "pathstream/host/modbus_stream.hpp"

namespace pathstream::host {

/// What the journal recorded of the job (JobJournal's fields of the same names).
struct ResumeJournal {
    std::uint32_t job = 0;             ///< the job's first sequence number; 0: no batch was sent
    std::uint32_t epoch = 0;           ///< the device's queue epoch at the last read
    std::uint32_t last_completed = 0;  ///< the last sequence number executed to its end
    bool finished = false;             ///< the outcome is "finished"
};

/// How far the wait for a device that still runs the job from its queue has come.
struct ResumeWait {
    bool waiting = false;       ///< the wait began (the device ran the job at the first read)
    bool held_at_rest = false;  ///< the device took the hold sent where it rests
    bool timed_out = false;     ///< the wait's time ran out: decide from the status as it is
};

enum class ResumeKind {
    kAlreadyFinished,    ///< the journal says the job ran to its end: nothing to do
    kReadDevice,         ///< read the device's status and decide again
    kWaitForQueue,       ///< the device runs the job from its queue: wait until it holds or ends
    kFinishedWhileAway,  ///< the device ran the job to its end: record it finished
    kContinueHeld,       ///< the device holds the job: stream the rest (`held`), then resume
    kReenter,            ///< the device is idle: re-enter the job from where it rests
    kRefuse,             ///< nothing can be done until the operator acts (`refusal`)
};

/// What to do next, with what that needs.
struct ResumeDecision {
    ResumeKind kind = ResumeKind::kReadDevice;
    /// kWaitForQueue: everything the device accepted has run and it still runs, waiting at rest
    /// for more where no underrun comes (a span that ends at rest: a pen change's dwell, an
    /// exact stop): send a hold now, as an underrun would have held it.
    bool hold_at_rest = false;
    HeldJob held;  ///< kContinueHeld: the job and the device's last accepted sequence number
    /// kContinueHeld, kReenter: the job's index of its first span not executed to its end.
    std::size_t first = 0;
    /// kReenter: the device does not know the job (it restarted, or its epoch changed), so
    /// `first` comes from the journal's last record.
    bool from_journal = false;
    /// kRefuse: why, without the target: "device has 2 axes, the profile 3", "device is holding
    /// another job: stop it first (...), then resume", "device is fault (...): reset it first
    /// (...), then resume".
    std::string refusal;
};

/// The next step of a resume. `spans`: the job's span count (JobSpans::plan); `axes`: the
/// machine profile's axis count; `device`: the last status read, nullptr before the first.
/// In order: a journal that says finished is kAlreadyFinished (the device is never asked);
/// without a status, kReadDevice; while the wait has not timed out, kWaitForQueue when the
/// device runs the job (its last accepted span one of the job's) at the first read, and after
/// that as long as it runs, or holds still moving to rest; an axis count other than the
/// profile's is refused; an idle device whose finished job is this one, in the journal's
/// epoch, with every span completed, is kFinishedWhileAway; a device that holds the job,
/// configured, in the journal's epoch, is kContinueHeld; any other state than idle is refused;
/// an idle device is kReenter from its own last completed span when it knows the job, else
/// from the journal's (0 when no span of the job had completed or none was sent).
ResumeDecision decide_resume(const ResumeJournal& journal, std::size_t spans, std::size_t axes,
                             const DeviceSnapshot* device, const ResumeWait& wait = {});

}  // namespace pathstream::host
