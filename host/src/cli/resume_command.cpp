// `pathstream stream --resume JOURNAL`: the journal and the device's status decide
// (resume_decision), then the rest of the job streams, held or re-entered (resume_path).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <thread>

#include "job_recipe.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/job_journal.hpp"
#include "pathstream/host/resume_decision.hpp"
#include "pathstream/host/resume_path.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/input_error.hpp"
#include "plan_command.hpp"
#include "stream_job.hpp"

namespace pathstream::host {

// What comes after each programmed pause of a plan in memory (pause_description of each).
std::vector<std::string> pause_descriptions(const Path& path, const Plan& plan) {
    std::vector<std::string> out;
    for (const PlanPause& p : plan.pauses) out.push_back(pause_description(path, p.subpath));
    return out;
}

// A journal whose plan was not complete when the stream ended (a host crash while planning):
// the job planned again from the drawing's copy with the same options, proved against every
// span the stream had handed on (the partial spans file), its spans file written and the
// journal updated. Throws InputError when it cannot be, naming what changed.
JobSpans replan_for_resume(JobJournal& journal, const std::string& journal_path,
                           const std::string& machine_file) {
    if (journal.replan.empty()) {
        throw InputError(
            journal_path, {},
            "the job's plan was never complete and the journal has no \"replan\" (written by an "
            "older "
            "pathstream, or --plan-first): nothing to go on from; stream the drawing again");
    }
    const JobRecipe recipe = parse_job_recipe(journal.replan, journal_path);
    if (const std::string h = file_content_hash(recipe.path.file); h != recipe.input_hash) {
        throw InputError(recipe.path.file, {},
                         "the drawing's copy changed since the job started (hash " + h +
                             ", journal " + recipe.input_hash + "): stream the drawing again");
    }
    if (const std::string h = file_content_hash(machine_file); h != recipe.machine_hash) {
        throw InputError(machine_file, {},
                         "the machine profile changed since the job started (hash " + h +
                             ", journal " + recipe.machine_hash +
                             "): resume with the profile the job was planned for");
    }
    std::printf(
        "resume        the plan was not complete when the stream ended: planning the job again "
        "from %s\n",
        recipe.path.file.c_str());
    std::fflush(stdout);
    const PlannedJob planned =
        plan_job(recipe.path, machine_file, recipe.lead_in_from ? &*recipe.lead_in_from : nullptr);
    JobSpans job = job_from_plan(planned.plan);
    // Every span the stream handed on is in the partial file, flushed before it left the
    // planner: the new plan must begin with exactly those lines. Planning may have ended (the
    // spans file written, the partial one removed) just before the journal could say so: then
    // the spans file is the proof.
    const std::string partial = partial_spans_path(journal.plan_file);
    std::string proof = partial;
    std::ifstream in(partial, std::ios::binary);
    std::size_t skip = 0;
    if (!in) {
        in.clear();
        in.open(journal.plan_file, std::ios::binary);
        proof = journal.plan_file;
        skip = 2;  // its header lines
    }
    if (!in && journal.job != 0) {
        throw InputError(journal_path, {},
                         "spans were sent, but neither " + partial + " nor " + journal.plan_file +
                             " is there to prove a new plan against: stream the drawing again");
    }
    std::string line;
    std::size_t proved = 0;
    std::size_t number = 0;
    while (in && std::getline(in, line)) {
        ++number;
        if (in.eof()) break;  // a last line without its newline was never flushed whole
        if (number <= skip) continue;
        if (proved >= job.plan.spans.size() ||
            line != job_span_line(job.plan.spans[proved], job.origin[proved],
                                  job.drawing_tick[proved])) {
            throw InputError(proof, {number, 1},
                             "the job planned again differs from the one streamed at span " +
                                 std::to_string(proved + 1) + " (planned by " + recipe.planner +
                                 ", now " + planner_identity() + "): stream the drawing again");
        }
        ++proved;
    }
    std::printf(
        "resume        planned again: %zu spans, the first %zu identical to the ones streamed\n",
        job.plan.spans.size(), proved);
    journal.plan_hash = write_job_spans(job, journal.plan_file);
    journal.pauses = pause_descriptions(planned.path, planned.plan);
    write_journal(journal, journal_path);
    std::remove(partial.c_str());
    return job;
}

// --resume: the device holds the job (go on streaming, then resume), or rests idle (a
// re-entry from where it rests to the first span not executed, then the rest of the job).
// decide_resume says which; this reads the device, waits, prints and acts.
int run_resume(StreamCommandOptions o, const EventChannel& channel) {
    JobJournal journal = read_journal(o.resume);
    if (o.machine.empty()) o.machine = journal.machine;
    if (o.stream.target.empty()) o.stream.target = journal.target;
    const MachineProfile machine = load_machine_profile(o.machine);
    const JobSpans job = journal.plan_hash.empty()
                             ? replan_for_resume(journal, o.resume, o.machine)
                             : read_job_spans(journal.plan_file, journal.plan_hash);
    const std::size_t spans = job.plan.spans.size();
    const std::size_t axes = machine.axes.size();
    const ResumeJournal record{journal.job, journal.epoch, journal.last_completed,
                               journal.outcome == "finished"};
    ResumeDecision d = decide_resume(record, spans, axes, nullptr);
    if (d.kind == ResumeKind::kAlreadyFinished) {
        std::printf("resume        %s: the job already ran to its end; nothing to do\n",
                    o.resume.c_str());
        return 0;
    }
    LinkOptions l;
    l.response_timeout_ms = o.stream.response_timeout_ms;
    l.attempts = o.stream.attempts;
    l.link_timeout_seconds = o.stream.link_timeout_seconds;
    DeviceSnapshot s;
    {
        const std::unique_ptr<DeviceLink> link = open_device_link(o.stream.target, l);
        s = link->status();
        // The wait for a device running out its queue lasts at most the queue's length in
        // time, bounded by the link timeout per quiet read.
        ResumeWait wait;
        std::chrono::steady_clock::time_point deadline;
        for (d = decide_resume(record, spans, axes, &s, wait); d.kind == ResumeKind::kWaitForQueue;
             d = decide_resume(record, spans, axes, &s, wait)) {
            if (!wait.waiting) {
                std::printf(
                    "resume        the device still runs job %u from its queue: waiting until it "
                    "holds or ends\n",
                    journal.job);
                std::fflush(stdout);
                wait.waiting = true;
                deadline = std::chrono::steady_clock::now() + std::chrono::seconds(600);
            }
            if (std::chrono::steady_clock::now() >= deadline) {
                wait.timed_out = true;
                continue;
            }
            if (d.hold_at_rest) {
                wait.held_at_rest = link->command(device::Command::kHold) == Status::kOk;
                if (wait.held_at_rest) {
                    std::printf(
                        "resume        the device ran out its queue at rest: holding it there\n");
                    std::fflush(stdout);
                }
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            s = link->status();
        }
    }
    if (d.kind == ResumeKind::kRefuse) throw StreamError(o.stream.target + ": " + d.refusal);
    if (d.kind == ResumeKind::kFinishedWhileAway) {
        JobJournal done = journal;
        done.outcome = "finished";
        done.last_completed = s.last_completed;
        done.state = device_state_name(s.state);
        done.position.assign(s.position, s.position + axes);
        write_journal(done, o.resume);
        std::printf(
            "resume        the device ran job %u to its end after the host stopped; nothing to "
            "do\n",
            journal.job);
        return 0;
    }
    if (d.kind == ResumeKind::kContinueHeld) {
        std::printf(
            "resume        the device holds job %u at span %u of %zu: streaming the rest, then "
            "resume\n",
            journal.job, static_cast<unsigned>(d.first), spans);
        PlanSupply supply(job.plan);
        return stream_job({supply, &job, nullptr, nullptr, nullptr, job.subpaths, {}}, machine, o,
                          journal, o.resume, &d.held, channel);
    }
    // kReenter: the only decision left once the device was read and the wait is over.
    const std::size_t first = d.first;
    if (d.from_journal) {
        std::printf(
            "resume        the device does not know job %u (restarted?): from the journal's last "
            "record, "
            "span %zu\n",
            journal.job, first);
    }
    std::vector<Lsb> rest(s.position, s.position + axes);
    const JobSpans resumed = resume_from(job, first, rest, device_limits(machine),
                                         delay_ticks(machine.spindle.spin_up, machine.tick_hz));
    std::printf(
        "resume        from where the device rests, back onto the drawing at span %lld of %zu "
        "(tick %llu)\n",
        static_cast<long long>(resumed.origin[resumed.origin.size() - (spans - first)]) + 1,
        job.drawing_spans, static_cast<unsigned long long>(resumed.drawing_tick.front()));
    JobJournal next = journal;
    next.job = 0;
    next.outcome = "streaming";
    next.error.clear();
    PlanSupply supply(resumed.plan);
    return stream_job({supply, &resumed, nullptr, nullptr, nullptr, resumed.subpaths, {}}, machine,
                      o, next, o.resume, nullptr, channel);
}

}  // namespace pathstream::host
