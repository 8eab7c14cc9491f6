// What `stream --resume` does with a journaled job, from the journal and the device status alone.
#include "pathstream/host/resume_decision.hpp"

#include <string>
#include <utility>

#include "pathstream/device/device_state.hpp"
#include "pathstream/machine/device_setup.hpp"

namespace pathstream::host {
namespace {

// The device's queue holds or held the job: its last accepted span is one of the job's, and
// its last completed one is at most the span before the job's first.
bool runs_job(const ResumeJournal& j, std::size_t spans, const DeviceSnapshot& s) {
    return j.job != 0 && s.last_accepted >= j.job && s.last_accepted - j.job < spans &&
           s.last_completed + 1 >= j.job;
}

ResumeDecision decision(ResumeKind kind) {
    ResumeDecision d;
    d.kind = kind;
    return d;
}

ResumeDecision refusal(std::string why) {
    ResumeDecision d = decision(ResumeKind::kRefuse);
    d.refusal = std::move(why);
    return d;
}

}  // namespace

ResumeDecision decide_resume(const ResumeJournal& journal, std::size_t spans, std::size_t axes,
                             const DeviceSnapshot* device, const ResumeWait& wait) {
    using device::DeviceState;
    if (journal.finished) return decision(ResumeKind::kAlreadyFinished);
    if (device == nullptr) return decision(ResumeKind::kReadDevice);
    const DeviceSnapshot& s = *device;
    const bool running = s.state == DeviceState::kRunning;
    const bool holding = s.state == DeviceState::kHolding;
    const bool ours = runs_job(journal, spans, s);
    // A host that died mid-stream leaves the device running out what it had queued: it then
    // holds (underrun) or, with the whole job queued, ends it. Once waiting, a hold still
    // coming to rest is waited for too (the hold sent at rest below).
    if (!wait.timed_out &&
        (wait.waiting ? running || (holding && s.own_move()) : running && ours)) {
        ResumeDecision d = decision(ResumeKind::kWaitForQueue);
        d.hold_at_rest = !wait.held_at_rest && running && s.last_completed == s.last_accepted;
        return d;
    }
    if (s.axes != axes) {
        return refusal("device has " + std::to_string(s.axes) + " axes, the profile " +
                       std::to_string(axes));
    }
    // Everything was queued before the host died, and the device ran it to its end.
    if (s.state == DeviceState::kIdle && journal.job != 0 && s.finished_job == journal.job &&
        s.epoch == journal.epoch && s.last_completed + 1 - journal.job == spans) {
        return decision(ResumeKind::kFinishedWhileAway);
    }
    // A restarted device (not configured) or a new epoch (its queue dropped since) no longer
    // holds the spans the journal sent, whatever its sequence numbers say.
    if (holding && ours && s.epoch == journal.epoch && s.configured()) {
        ResumeDecision d = decision(ResumeKind::kContinueHeld);
        d.held = HeldJob{journal.job, s.last_accepted};
        d.first = s.last_completed + 1 - journal.job;
        return d;
    }
    if (s.state != DeviceState::kIdle) {
        return refusal(std::string("device is ") + device_state_name(s.state) +
                       fault_suffix(s.state, s.fault_code) +
                       (holding ? " another job: stop it first (pathstream ctl TARGET stop)"
                                : ": reset it first (pathstream ctl TARGET reset)") +
                       ", then resume");
    }
    ResumeDecision d = decision(ResumeKind::kReenter);
    if (ours) {
        d.first = s.last_completed + 1 - journal.job;
    } else if (journal.job != 0 && journal.last_completed + 1 >= journal.job) {
        d.first = journal.last_completed + 1 - journal.job;
        d.from_journal = true;
    }
    return d;
}

}  // namespace pathstream::host
