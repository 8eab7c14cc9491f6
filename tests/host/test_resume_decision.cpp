// decide_resume, the decision `stream --resume` acts on, case by case: a device that ran the job
// on after the host died, holds it, rests idle knowing it or not (restarted, a new epoch), or
// cannot take it. The journal's job is sequence numbers 100 to 109 (10 spans) on 2 axes.
#include <catch2/catch.hpp>
#include <cstdint>
#include <string>

#include "pathstream/device/device_state.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/resume_decision.hpp"

using namespace pathstream;
using device::DeviceState;
using host::DeviceSnapshot;
using host::ResumeDecision;
using host::ResumeJournal;
using host::ResumeKind;
using host::ResumeWait;

namespace {

constexpr std::uint32_t kJob = 100;
constexpr std::size_t kSpans = 10;
constexpr std::size_t kAxes = 2;

ResumeJournal journal_at(std::uint32_t last_completed) {
    ResumeJournal j;
    j.job = kJob;
    j.epoch = 7;
    j.last_completed = last_completed;
    return j;
}

// A configured device in the journal's epoch with the profile's axes.
DeviceSnapshot device_in(DeviceState state, std::uint32_t last_accepted,
                         std::uint32_t last_completed) {
    DeviceSnapshot s;
    s.state = state;
    s.axes = kAxes;
    s.epoch = 7;
    s.flags = DeviceSnapshot::kSnapshotConfigured;
    s.last_accepted = last_accepted;
    s.last_completed = last_completed;
    return s;
}

ResumeDecision decide(const ResumeJournal& j, const DeviceSnapshot& s, const ResumeWait& w = {}) {
    return host::decide_resume(j, kSpans, kAxes, &s, w);
}

ResumeWait waiting() {
    ResumeWait w;
    w.waiting = true;
    return w;
}

const char* const kResetFirst = ": reset it first (pathstream ctl TARGET reset), then resume";
const char* const kAnotherJob =
    "device is holding another job: stop it first (pathstream ctl TARGET stop), then resume";

}  // namespace

TEST_CASE("resume decision: a journal that says finished never asks the device", "[resume]") {
    ResumeJournal j = journal_at(109);
    j.finished = true;
    CHECK(host::decide_resume(j, kSpans, kAxes, nullptr).kind == ResumeKind::kAlreadyFinished);
    // Whatever the device says, even of another machine.
    DeviceSnapshot s = device_in(DeviceState::kFault, 0, 0);
    s.axes = 3;
    CHECK(decide(j, s).kind == ResumeKind::kAlreadyFinished);
}

TEST_CASE("resume decision: an unfinished journal reads the device first", "[resume]") {
    CHECK(host::decide_resume(journal_at(103), kSpans, kAxes, nullptr).kind ==
          ResumeKind::kReadDevice);
    ResumeJournal none;  // no batch was ever sent
    CHECK(host::decide_resume(none, kSpans, kAxes, nullptr).kind == ResumeKind::kReadDevice);
}

TEST_CASE("resume decision: a device running the job from its queue is waited for", "[resume]") {
    const ResumeJournal j = journal_at(103);
    SECTION("mid-queue: wait, no hold") {
        const ResumeDecision d = decide(j, device_in(DeviceState::kRunning, 106, 103));
        CHECK(d.kind == ResumeKind::kWaitForQueue);
        CHECK_FALSE(d.hold_at_rest);
    }
    SECTION("the sequence numbers at the job's first span, none completed") {
        const ResumeDecision d = decide(j, device_in(DeviceState::kRunning, kJob, kJob - 1));
        CHECK(d.kind == ResumeKind::kWaitForQueue);
        CHECK_FALSE(d.hold_at_rest);  // its first span still runs
    }
    SECTION("its last accepted span past the job's last: another job, not waited for") {
        const ResumeDecision d = decide(j, device_in(DeviceState::kRunning, 110, 105));
        CHECK(d.kind == ResumeKind::kRefuse);
        CHECK(d.refusal == std::string("device is running") + kResetFirst);
    }
    SECTION("its last accepted span before the job's first: not waited for") {
        const ResumeDecision d = decide(j, device_in(DeviceState::kRunning, 99, 90));
        CHECK(d.kind == ResumeKind::kRefuse);
    }
    SECTION("a job of no batch is never the one running") {
        const ResumeDecision d = decide(ResumeJournal{}, device_in(DeviceState::kRunning, 5, 3));
        CHECK(d.kind == ResumeKind::kRefuse);
    }
    SECTION("the wait comes before the axis check") {
        DeviceSnapshot s = device_in(DeviceState::kRunning, 106, 103);
        s.axes = 3;
        CHECK(decide(j, s).kind == ResumeKind::kWaitForQueue);
        ResumeWait over = waiting();
        over.timed_out = true;
        CHECK(decide(j, s, over).refusal == "device has 3 axes, the profile 2");
    }
}

TEST_CASE("resume decision: running with everything accepted completed is held at rest, once",
          "[resume]") {
    const ResumeJournal j = journal_at(103);
    const DeviceSnapshot s = device_in(DeviceState::kRunning, 105, 105);
    ResumeDecision d = decide(j, s);
    CHECK(d.kind == ResumeKind::kWaitForQueue);
    CHECK(d.hold_at_rest);
    ResumeWait w = waiting();
    CHECK(decide(j, s, w).hold_at_rest);  // the hold was refused: send it again
    w.held_at_rest = true;
    d = decide(j, s, w);
    CHECK(d.kind == ResumeKind::kWaitForQueue);
    CHECK_FALSE(d.hold_at_rest);
    // Holding still decelerates: no hold is sent to a device not running.
    DeviceSnapshot moving = device_in(DeviceState::kHolding, 105, 105);
    moving.flags |= DeviceSnapshot::kSnapshotOwnMove;
    d = decide(j, moving, waiting());
    CHECK(d.kind == ResumeKind::kWaitForQueue);
    CHECK_FALSE(d.hold_at_rest);
}

TEST_CASE("resume decision: the wait lasts while it runs or holds still moving, until timed out",
          "[resume]") {
    const ResumeJournal j = journal_at(103);
    // Once waiting, a run of any numbers is waited out (the first read said it was ours).
    CHECK(decide(j, device_in(DeviceState::kRunning, 200, 150), waiting()).kind ==
          ResumeKind::kWaitForQueue);
    DeviceSnapshot moving = device_in(DeviceState::kHolding, 107, 104);
    moving.flags |= DeviceSnapshot::kSnapshotOwnMove;
    CHECK(decide(j, moving, waiting()).kind == ResumeKind::kWaitForQueue);
    // A hold still moving at the first read is not waited for: it holds the job.
    CHECK(decide(j, moving).kind == ResumeKind::kContinueHeld);
    // At rest, the wait ends with the held job.
    const ResumeDecision d = decide(j, device_in(DeviceState::kHolding, 107, 104), waiting());
    CHECK(d.kind == ResumeKind::kContinueHeld);
    CHECK(d.first == 5);
    // Out of time: what the device is doing then decides.
    ResumeWait over = waiting();
    over.timed_out = true;
    const ResumeDecision late = decide(j, device_in(DeviceState::kRunning, 107, 104), over);
    CHECK(late.kind == ResumeKind::kRefuse);
    CHECK(late.refusal == std::string("device is running") + kResetFirst);
}

TEST_CASE("resume decision: the device ran the whole job to its end while the host was away",
          "[resume]") {
    const ResumeJournal j = journal_at(104);
    DeviceSnapshot s = device_in(DeviceState::kIdle, 109, 109);
    s.finished_job = kJob;
    CHECK(decide(j, s).kind == ResumeKind::kFinishedWhileAway);
    SECTION("another job finished: a re-entry at the end, which finds nothing to draw") {
        s.finished_job = 57;
        const ResumeDecision d = decide(j, s);
        CHECK(d.kind == ResumeKind::kReenter);
        CHECK(d.first == kSpans);
    }
    SECTION("a new epoch: the queue was dropped since, not finished") {
        s.epoch = 8;
        CHECK(decide(j, s).kind == ResumeKind::kReenter);
    }
    SECTION("one span short of the end: the rest re-entered") {
        s.last_completed = 108;
        const ResumeDecision d = decide(j, s);
        CHECK(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 9);
        CHECK_FALSE(d.from_journal);
    }
    SECTION("not idle: not finished") {
        s.state = DeviceState::kFault;
        CHECK(decide(j, s).kind == ResumeKind::kRefuse);
    }
}

TEST_CASE("resume decision: a device that holds the job streams the rest, then resumes",
          "[resume]") {
    const ResumeJournal j = journal_at(102);
    SECTION("mid-job") {
        const ResumeDecision d = decide(j, device_in(DeviceState::kHolding, 106, 103));
        REQUIRE(d.kind == ResumeKind::kContinueHeld);
        CHECK(d.held.job == kJob);
        CHECK(d.held.acknowledged == 106);
        CHECK(d.first == 4);
    }
    SECTION("its first span accepted, none executed (last completed the job's first - 1)") {
        const ResumeDecision d = decide(j, device_in(DeviceState::kHolding, kJob, kJob - 1));
        REQUIRE(d.kind == ResumeKind::kContinueHeld);
        CHECK(d.held.acknowledged == kJob);
        CHECK(d.first == 0);
    }
    SECTION("its last span accepted") {
        const ResumeDecision d = decide(j, device_in(DeviceState::kHolding, 109, 107));
        REQUIRE(d.kind == ResumeKind::kContinueHeld);
        CHECK(d.first == 8);
    }
    SECTION("a new epoch: its queue is another's") {
        DeviceSnapshot s = device_in(DeviceState::kHolding, 106, 103);
        s.epoch = 8;
        const ResumeDecision d = decide(j, s);
        CHECK(d.kind == ResumeKind::kRefuse);
        CHECK(d.refusal == kAnotherJob);
    }
    SECTION("restarted (not configured): the numbers are not the job's") {
        DeviceSnapshot s = device_in(DeviceState::kHolding, 106, 103);
        s.flags = 0;
        CHECK(decide(j, s).refusal == kAnotherJob);
    }
    SECTION("holding another job") {
        CHECK(decide(j, device_in(DeviceState::kHolding, 130, 120)).refusal == kAnotherJob);
        CHECK(decide(j, device_in(DeviceState::kHolding, 99, 95)).refusal == kAnotherJob);
    }
}

TEST_CASE("resume decision: an idle device is re-entered from where the job stands", "[resume]") {
    SECTION("the device knows the job: from its last completed span") {
        const ResumeDecision d = decide(journal_at(101), device_in(DeviceState::kIdle, 106, 103));
        REQUIRE(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 4);
        CHECK_FALSE(d.from_journal);
    }
    SECTION("the device knows the job, none of it executed") {
        const ResumeDecision d =
            decide(journal_at(kJob - 1), device_in(DeviceState::kIdle, 104, kJob - 1));
        REQUIRE(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 0);
        CHECK_FALSE(d.from_journal);
    }
    SECTION("restarted (not configured, numbers from 0): from the journal's last record") {
        DeviceSnapshot s = device_in(DeviceState::kIdle, 0, 0);
        s.flags = 0;
        const ResumeDecision d = decide(journal_at(104), s);
        REQUIRE(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 5);
        CHECK(d.from_journal);
    }
    SECTION("another job since: from the journal's last record") {
        const ResumeDecision d = decide(journal_at(106), device_in(DeviceState::kIdle, 300, 300));
        REQUIRE(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 7);
        CHECK(d.from_journal);
    }
    SECTION("the journal recorded none executed (last completed the job's first - 1)") {
        const ResumeDecision d = decide(journal_at(kJob - 1), device_in(DeviceState::kIdle, 0, 0));
        REQUIRE(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 0);
        CHECK(d.from_journal);
    }
    SECTION("the journal's last record before the job's first span: from its start") {
        const ResumeDecision d = decide(journal_at(40), device_in(DeviceState::kIdle, 0, 0));
        REQUIRE(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 0);
        CHECK_FALSE(d.from_journal);
    }
    SECTION("no batch was ever sent: from the start") {
        const ResumeDecision d = decide(ResumeJournal{}, device_in(DeviceState::kIdle, 55, 55));
        REQUIRE(d.kind == ResumeKind::kReenter);
        CHECK(d.first == 0);
        CHECK_FALSE(d.from_journal);
    }
}

TEST_CASE("resume decision: refusals name the axes or the state to leave first", "[resume]") {
    const ResumeJournal j = journal_at(103);
    SECTION("axes: checked before anything else but the wait") {
        DeviceSnapshot s = device_in(DeviceState::kHolding, 106, 103);
        s.axes = 3;
        const ResumeDecision d = decide(j, s);
        CHECK(d.kind == ResumeKind::kRefuse);
        CHECK(d.refusal == "device has 3 axes, the profile 2");
        CHECK(host::decide_resume(j, kSpans, 3, &s).kind == ResumeKind::kContinueHeld);
    }
    SECTION("a fault, named") {
        DeviceSnapshot s = device_in(DeviceState::kFault, 106, 103);
        s.fault_code = static_cast<std::uint16_t>(device::FaultCode::kExternal);
        CHECK(decide(j, s).refusal ==
              std::string("device is fault (external fault)") + kResetFirst);
    }
    SECTION("e-stop and stopping") {
        CHECK(decide(j, device_in(DeviceState::kEstop, 106, 103)).refusal ==
              std::string("device is e-stop") + kResetFirst);
        CHECK(decide(j, device_in(DeviceState::kStopping, 106, 103)).refusal ==
              std::string("device is stopping") + kResetFirst);
    }
}
