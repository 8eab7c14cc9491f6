#include "stream_command.hpp"

#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include "job_recipe.hpp"
#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/cia402_master.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/events.hpp"
#include "pathstream/host/job_estimate.hpp"
#include "pathstream/host/job_journal.hpp"
#include "pathstream/host/mqtt_client.hpp"
#include "pathstream/host/planning_thread.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/host/resume_decision.hpp"
#include "pathstream/host/resume_path.hpp"
#include "pathstream/host/span_supply.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/input_error.hpp"
#include "plan_command.hpp"
#include "serve/child_process.hpp"
#include "serve/stream_reporter.hpp"
#include "stream_job.hpp"
#include "stream_plan_tap.hpp"

namespace pathstream::host {

void add_stream_command(CLI::App& app, StreamCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand("stream",
                                       "Plan the path and stream it to a device running the core "
                                       "over Modbus TCP or RTU (docs/modbus.md) or native "
                                       "CAN (docs/can.md), or to CiA 402 drives in cyclic "
                                       "synchronous position mode (docs/cia402.md)");
    add_path_options(*cmd, o.path);
    // FILE, --machine and --target come from the journal with --resume.
    cmd->get_option("file")->required(false);
    cmd->add_option("--machine,-m", o.machine,
                    "machine profile (JSON, docs/formats.md); required unless --resume")
        ->check(CLI::ExistingFile);
    cmd->add_option("--target,-t", o.stream.target,
                    "device: modbus-tcp://HOST:PORT?unit=N, "
                    "modbus-rtu:///dev/ttyX?baud=115200&parity=N&unit=1, "
                    "can://IFACE?node=N&protocol=native or CiA 402 drives "
                    "can://IFACE?node=N&protocol=cia402&cycle=2ms; required unless --resume");
    CLI::Option* lead_in = cmd->add_flag(
        "--lead-in", o.lead_in,
        "start with a pen-up move from where the device rests (e.g. after homing) to the drawing's "
        "first point: the default for Modbus and native CAN targets");
    cmd->add_flag(
           "--no-lead-in", o.no_lead_in,
           "plan no lead-in: refuse a device that does not rest at the drawing's first point")
        ->excludes(lead_in);
    cmd->add_option("--journal", o.journal,
                    "job journal, written as the stream goes, for --resume (default: "
                    "DRAWING.journal.json in the "
                    "current directory, DRAWING the file's name without its extension)");
    cmd->add_flag("--no-journal", o.no_journal, "write no job journal");
    cmd->add_flag(
        "--replace-journal", o.replace_journal,
        "start anew even when the journal holds a job that did not finish (it is replaced)");
    cmd->add_flag(
        "--plan-first", o.plan_first,
        "plan the whole job before sending anything (the events' totals are known from job_start; "
        "memory grows with the job) instead of streaming while the planner works");
    cmd->add_option(
           "--resume", o.resume,
           "continue the drawing of this job journal after a Ctrl-C, a stop, a fault reset, a "
           "device "
           "restart or a host crash (FILE, --machine and --target default to the journal's)")
        ->check(CLI::ExistingFile);
    cmd->add_option(
           "--hold-timeout", o.hold_timeout_seconds,
           "Ctrl-C: seconds for the hold to come to rest before the device is stopped instead")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 600.0));
    cmd->add_option("--lead", o.stream.lead_seconds,
                    "seconds of motion kept queued ahead of the device (Modbus, native CAN)")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 60.0));
    cmd->add_option("--timeout-ms", o.stream.response_timeout_ms,
                    "response timeout per Modbus try (native CAN: wait for an answer before "
                    "resending, at most 100)")
        ->capture_default_str()
        ->check(CLI::Range(10u, 60000u));
    cmd->add_option("--attempts", o.stream.attempts,
                    "tries per Modbus transaction before reconnecting")
        ->capture_default_str()
        ->check(CLI::Range(1u, 100u));
    cmd->add_option("--link-timeout", o.stream.link_timeout_seconds,
                    "give up after this many seconds without an answer (Modbus, native CAN)")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 3600.0));
    cmd->add_option(
        "--events", o.events,
        "write the job's events as NDJSON to this file (docs/events.md); -: standard output, the "
        "text report then goes to standard error");
    cmd->add_option("--events-rate", o.events_rate,
                    "progress events per second, at most (with --events)")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 1000.0));
    cmd->add_option("--mqtt", o.mqtt,
                    "report the job to this MQTT broker and take operator commands from it, as "
                    "serve --mqtt does: mqtt[s]://[USER[:PASSWORD]@]HOST[:PORT][?...] "
                    "(docs/mqtt.md)");
    cmd->add_option("--name", o.name,
                    "the machine's name on the broker (topics pathstream/NAME/...)")
        ->needs(cmd->get_option("--mqtt"));
}

namespace {

// Ctrl-C and SIGTERM: the first asks for a hold, the second for a stop (StreamInterrupt).
std::atomic<int> g_interrupts{0};
extern "C" void on_stream_signal(int) {
    const int n = g_interrupts.fetch_add(1) + 1;
    static const char hold[] =
        "\npathstream: interrupt: holding from the current tick (Ctrl-C again: stop and drop the "
        "queue)\n";
    static const char stop[] = "\npathstream: interrupt: stopping\n";
    if (n == 1) {
        (void)!write(2, hold, sizeof hold - 1);
    } else if (n == 2) {
        (void)!write(2, stop, sizeof stop - 1);
    }
}

// Keeps the journal file in step with the stream: at most five writes a second, and at once
// when the state or the acknowledged span changes kind (an interrupt, a fault).
class JournalWriter {
public:
    JournalWriter(std::string path, JobJournal journal)
        : path_(std::move(path)), journal_(std::move(journal)) {
        if (!path_.empty()) write_journal(journal_, path_);
    }

    void trace(const StreamTrace& t) {
        if (path_.empty()) return;
        const std::string state = device_state_name(t.status.state);
        const bool changed = state != journal_.state || t.job != journal_.job;
        journal_.job = t.job;
        journal_.acknowledged = t.acknowledged;
        journal_.last_completed = t.status.last_completed;
        journal_.epoch = t.status.epoch;
        journal_.state = state;
        journal_.position.assign(t.status.position,
                                 t.status.position + std::min<unsigned>(t.status.axes, kMaxAxes));
        const auto now = std::chrono::steady_clock::now();
        if (changed || now - last_write_ > std::chrono::milliseconds(200)) {
            write_journal(journal_, path_);
            last_write_ = now;
        }
    }

    void finish(const std::string& outcome, const std::string& error = "") {
        if (path_.empty()) return;
        journal_.outcome = outcome;
        journal_.error = error;
        write_journal(journal_, path_);
    }

    const std::string& path() const { return path_; }
    const JobJournal& journal() const { return journal_; }

    /// What comes after the drawing's next programmed pause (in order, as planning finds them).
    void add_pause(std::string next) { journal_.pauses.push_back(std::move(next)); }
    /// The job's spans file is complete: recorded with its hash at the next write.
    void set_plan_hash(std::string hash) { journal_.plan_hash = std::move(hash); }

private:
    std::string path_;
    JobJournal journal_;
    std::chrono::steady_clock::time_point last_write_{};
};

// The job as the streamer takes it, span by span: the events learn each span, the journal
// each pause's description (a job planned as it streams), and the spans not yet executed are
// kept for the report of where an interrupt stopped. Streaming thread only.
class TrackedSupply : public SpanSupply {
public:
    // `job`: the job held in memory (a resume; its places from there), null for a first job
    // planned as it streams (span i is the drawing's span i). `path`: describes the pauses of
    // a first job; null when the journal has them already.
    TrackedSupply(SpanSupply& inner, const JobSpans* job, JobEvents& events, JournalWriter& writer,
                  const Path* path)
        : inner_(inner), job_(job), events_(events), writer_(writer), path_(path) {}

    Take take(CoreSpan& out) override {
        const Take t = inner_.take(out);
        if (t == Take::kEnd && pause_pending_ && path_ != nullptr) {
            writer_.add_pause(pause_description(*path_, last_subpath_));
            pause_pending_ = false;
        }
        if (t != Take::kSpan) return t;
        SpanPlace place{static_cast<std::int64_t>(taken_), out.subpath, ticks_};
        if (job_ != nullptr)
            place = {job_->origin.at(taken_), out.subpath, job_->drawing_tick.at(taken_)};
        places_.push_back(place);
        events_.add_span(out);
        if (pause_pending_ && path_ != nullptr)
            writer_.add_pause(pause_description(*path_, out.subpath));
        pause_pending_ = out.pause_after;
        last_subpath_ = out.subpath;
        ticks_ += out.ticks;
        ++taken_;
        return t;
    }
    std::optional<std::uint64_t> total_ticks() const override { return inner_.total_ticks(); }

    // The job's spans before `index` were executed: their places are not needed again.
    void executed_before(std::size_t index) {
        while (places_base_ < index && !places_.empty()) {
            places_.pop_front();
            ++places_base_;
        }
    }
    // Where span `index` of the job sits, when it was taken and not forgotten.
    std::optional<SpanPlace> place(std::size_t index) const {
        if (index < places_base_ || index - places_base_ >= places_.size()) return std::nullopt;
        return places_[index - places_base_];
    }

private:
    SpanSupply& inner_;
    const JobSpans* job_;
    JobEvents& events_;
    JournalWriter& writer_;
    const Path* path_;
    std::deque<SpanPlace> places_;
    std::size_t places_base_ = 0;
    std::size_t taken_ = 0;
    std::uint64_t ticks_ = 0;
    bool pause_pending_ = false;
    std::size_t last_subpath_ = 0;
};

std::string default_journal_path(const std::string& drawing) {
    if (drawing == "-") return "stdin.journal.json";
    return std::filesystem::path(drawing).stem().string() + ".journal.json";
}

// True when the job of this journal never had a span accepted by the device: nothing of it
// moved, and a resume would only start it again. False when it cannot be read (kept then).
bool nothing_taken(const std::string& journal_path) {
    try {
        return read_journal(journal_path).nothing_accepted();
    } catch (const std::exception&) {
        return !std::filesystem::exists(journal_path);
    }
}

// A first stream that ends before the device took any of its spans (refused, unreachable,
// interrupted while planning) leaves no files: no journal, no spans file, no drawing copy.
class JobFilesGuard {
public:
    explicit JobFilesGuard(std::string journal_path) : journal_(std::move(journal_path)) {}
    JobFilesGuard(const JobFilesGuard&) = delete;
    JobFilesGuard& operator=(const JobFilesGuard&) = delete;
    ~JobFilesGuard() {
        if (journal_.empty() || !nothing_taken(journal_)) return;
        const std::string plan = std::filesystem::absolute(journal_ + ".plan").string();
        for (const std::string& f : {journal_, plan, partial_spans_path(plan),
                                     std::filesystem::absolute(journal_ + ".input").string()}) {
            std::error_code ignored;
            std::filesystem::remove(f, ignored);
        }
    }

private:
    std::string journal_;
};

// A second stream to the same journal (the default one of a drawing streamed again from the
// same directory, or the same --journal) would replace the journal of a job the device may
// still hold, and with it the only way to resume that job: refused, before anything is sent,
// unless that job ended, the device took nothing of it, or --replace-journal says so.
void refuse_unfinished_journal(const std::string& journal_path) {
    JobJournal old;
    try {
        old = read_journal(journal_path);
    } catch (const std::exception&) {
        return;  // none, or not a journal: nothing to keep
    }
    if (old.outcome == "finished" || old.nothing_accepted()) return;
    throw std::invalid_argument(journal_path + ": the journal of job " + std::to_string(old.job) +
                                " (" + old.outcome + ", device state " + old.state +
                                ") is there: continue it with `pathstream stream --resume " +
                                journal_path +
                                "`; to draw anew, give --replace-journal or another --journal");
}

// A line typed at the terminal (Enter) since the last look; never waits.
bool enter_pressed() {
    pollfd p{STDIN_FILENO, POLLIN, 0};
    if (::poll(&p, 1, 0) <= 0 || (p.revents & POLLIN) == 0) return false;
    char buffer[256];
    const ssize_t n = ::read(STDIN_FILENO, buffer, sizeof buffer);
    return n > 0 && std::memchr(buffer, '\n', static_cast<std::size_t>(n)) != nullptr;
}

// The operator's side of programmed pauses: a message (and an event) at each, and Enter at
// the terminal resumes when standard input is one that no path is read from. The pauses'
// descriptions are the journal's (a job planned as it streams adds them as they come).
void handle_pauses(InterruptOptions& interrupt, const JournalWriter& writer, JobEvents& events,
                   const std::string& target, bool terminal) {
    interrupt.on_pause = [&writer, &events, target, terminal](std::size_t index) {
        const std::vector<std::string>& pauses = writer.journal().pauses;
        const std::string next = index < pauses.size() ? pauses[index] : "the rest of the job";
        // A G-code stop or tool change says so (its note); others are a plotter's pen change.
        const bool noted =
            next.rfind("tool change", 0) == 0 || next.rfind("program stop", 0) == 0 ||
            next.rfind("optional stop", 0) == 0 || next.rfind("pallet change", 0) == 0;
        const std::string what = noted ? next : "a pen change, " + next + " next";
        std::fprintf(stderr, "\npathstream: paused for %s: %s `pathstream ctl %s resume`\n",
                     what.c_str(), terminal ? "press Enter to go on, or" : "go on with",
                     target.c_str());
        events.pause(index, next);
    };
    if (terminal) interrupt.resume_requested = enter_pressed;
}

// After a stream that ended early (an interrupt, a device error) while planning still runs:
// planning goes on to its end, for the journal's spans file that --resume needs, unless the
// operator interrupts again.
void finish_planning(PlanningThread& planning, bool journal) {
    if (planning.finished() || !journal) return;
    std::printf(
        "planning      the rest of the job, for --resume (Ctrl-C: skip it; --resume then plans it "
        "again)\n");
    std::fflush(stdout);
    const int interrupts = g_interrupts.load();
    planning.drain([interrupts] { return g_interrupts.load() == interrupts; });
}

}  // namespace

// Streams `job`, keeping the journal and writing the events; returns the exit status.
int stream_job(const JobToStream& job, const MachineProfile& machine, StreamCommandOptions o,
               JobJournal journal, const std::string& journal_path, const HeldJob* held,
               const EventChannel& channel) {
    const bool can = o.stream.target.rfind("can://", 0) == 0;
    if (!journal_path.empty()) {
        const std::string plan_file = std::filesystem::absolute(journal_path + ".plan").string();
        journal.plan_file = plan_file;
        // A job planned as it streams has its spans file once planning ends (set_plan_hash).
        journal.plan_hash = job.spans != nullptr ? write_job_spans(*job.spans, plan_file) : "";
        std::printf("journal       %s\n", journal_path.c_str());
    }
    JournalWriter writer(journal_path, journal);
    o.stream.interrupt.request = &g_interrupts;
    o.stream.interrupt.hold_timeout_seconds = o.hold_timeout_seconds;
    std::signal(SIGINT, on_stream_signal);
    std::signal(SIGTERM, on_stream_signal);
    JobEvents events(channel, machine, {"stream", journal.drawing, o.stream.target, job.subpaths});
    if (job.spans != nullptr) {
        events.set_totals(job.spans->plan.total_ticks, job.spans->plan.spans.size(),
                          job.spans->plan.pauses.size());
    }
    // A resume counts the whole drawing: what ran before it comes first.
    const std::uint64_t before =
        job.spans != nullptr && held == nullptr && !job.spans->drawing_tick.empty()
            ? job.spans->drawing_tick.front()
            : 0;
    events.set_progress_basis(before, job.estimate);
    TrackedSupply supply(job.supply, job.spans, events, writer,
                         job.spans == nullptr ? job.path : nullptr);
    handle_pauses(o.stream.interrupt, writer, events, o.stream.target,
                  o.path.file != "-" && ::isatty(STDIN_FILENO) == 1);
    // Once planning has ended: its totals go to the events, its spans file to the journal.
    bool plan_recorded = job.planning == nullptr;
    std::optional<DrawingTotals> totals;
    if (job.spans != nullptr)
        totals =
            DrawingTotals{job.spans->drawing_spans, job.spans->subpaths, job.spans->drawing_ticks};
    const auto record_plan = [&] {
        if (plan_recorded || !job.planning->finished()) return;
        plan_recorded = true;
        if (const std::optional<PlanTotals> t = job.planning->totals()) {
            events.set_totals(t->total_ticks, t->spans, t->pauses);
            totals = DrawingTotals{t->spans, job.subpaths, t->total_ticks};
            if (!journal_path.empty()) writer.set_plan_hash(job.tap->spans_hash());
        }
    };
    // Every status read goes to both records: the journal and the events.
    const StreamObserver observer = [&](const StreamTrace& t) {
        record_plan();
        if (t.job != 0 && t.status.last_completed + 1 >= t.job)
            supply.executed_before(t.status.last_completed + 1 - t.job);
        writer.trace(t);
        events.trace(t);
    };
    StreamEnd end;
    try {
        end = can ? stream_over_can(supply, machine, o, observer, held, events, job.planning)
                  : stream_over_modbus(supply, machine, o, observer, held, events, job.planning);
    } catch (const std::exception& e) {
        const bool taken = held != nullptr || !writer.journal().nothing_accepted();
        if (job.planning != nullptr) {
            if (taken) {
                finish_planning(*job.planning, !journal_path.empty());
            } else {
                job.planning->cancel();  // nothing to resume: no plan needed
            }
        }
        record_plan();
        writer.finish("failed", e.what());
        events.end("failed", e.what());
        if (!taken && !journal_path.empty() && held == nullptr && journal_path != o.resume) {
            std::printf("journal       none kept: the device took nothing of this job\n");
            std::fflush(stdout);
        } else if (!journal_path.empty() &&
                   (!writer.journal().plan_hash.empty() || !writer.journal().replan.empty())) {
            // A fault or e-stop stops the job where it is: once the device is reset, the journal
            // goes on from there.
            std::printf(
                "resume with   pathstream stream --resume %s (after pathstream ctl %s reset, if it "
                "faulted)\n",
                journal_path.c_str(), o.stream.target.c_str());
            std::fflush(stdout);
        }
        throw;
    }
    // The handler stays: a late second Ctrl-C must not cut the report of where it stopped.
    if (end.interrupted == 0) {
        record_plan();
        writer.finish("finished");
        events.end("finished", "", events.total_ticks());
        return 0;
    }
    if (end.stopped_elsewhere) {
        std::printf(
            "stopped       by another client (pathstream ctl stop, the page, another host): the "
            "device "
            "dropped the job's queue and is idle\n");
    }
    if (job.planning != nullptr) finish_planning(*job.planning, !journal_path.empty());
    record_plan();
    writer.finish(end.interrupted == 1 ? "held" : "stopped");
    events.end(end.interrupted == 1 ? "held" : "stopped");
    // The next span of the job that was not executed to its end (re-entry spans skipped).
    std::optional<SpanPlace> next;
    const DeviceSnapshot& s = end.status;
    std::size_t index = 0;
    if (end.job != 0 && s.last_completed + 1 >= end.job) index = s.last_completed + 1 - end.job;
    for (next = supply.place(index); next && next->origin < 0; next = supply.place(++index)) {
    }
    print_interrupted(end, next, totals, machine, writer.path(),
                      !writer.journal().plan_hash.empty() || !writer.journal().replan.empty());
    return kExitInterrupted;
}

namespace {

// CiA 402 drives: no device status to follow, so the events are the job's start and end.
int stream_cia402(const PlannedJob& planned, const std::string& url, const EventChannel& channel,
                  const std::string& drawing) {
    if (!planned.plan.pauses.empty()) {
        throw std::invalid_argument(
            "CiA 402 targets cannot pause the job (" + std::to_string(planned.plan.pauses.size()) +
            " programmed pauses: pen changes or M0/M1): plot one layer at a time with --layer, or "
            "turn the pen-change pauses off with --pause none");
    }
    hal::SocketCanBus cia402_bus(parse_cia402_target(url, planned.machine.axes.size()).interface);
    const JobSpans job = job_from_plan(planned.plan);
    JobEvents events(channel, planned.plan, planned.machine,
                     {"stream", drawing, url, job.subpaths});
    events.start(std::nullopt);
    try {
        const int status = run_cia402_stream(planned.plan, planned.machine, url, cia402_bus);
        events.end("finished", "", planned.plan.total_ticks);
        return status;
    } catch (const std::exception& e) {
        events.end("failed", e.what());
        throw;
    }
}

// Plans `job` on the planning thread and streams its spans as they come (docs/cli.md,
// "Planning while streaming"): the first batch goes out once the first window is planned.
int stream_while_planning(const PlannedJob& job, const StreamCommandOptions& o,
                          const JobJournal& journal, const std::string& journal_path,
                          const EventChannel& channel) {
    const std::string spans_file =
        journal_path.empty() ? "" : std::filesystem::absolute(journal_path + ".plan").string();
    StreamPlanTap tap(job, o.path.file, spans_file);
    PathSegmentSource source(job.path, job.lead_in);
    PlanningThread planning(source, job.machine, PlanOptions{},
                            {&tap, [&tap](const PlanTotals& totals) { tap.finish(totals); }});
    {
        // Until the first window is planned; a Ctrl-C meanwhile ends the command, nothing sent.
        ProgressBar bar("planning the first window");
        while (planning.queued() == 0 && !planning.finished()) {
            if (g_interrupts.load() > 0) {
                planning.cancel();
                bar.finish();
                std::printf("interrupted   while planning: nothing was sent to the device\n");
                return kExitInterrupted;
            }
            bar.update(planning.fraction());
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
        }
    }
    if (planning.finished() && !planning.totals()) {
        // Planning failed before a span was ready: its error, and nothing written or sent.
        CoreSpan none;
        (void)planning.take(none);
    }
    PathSegmentSource estimated(job.path, job.lead_in);
    const JobEstimate estimate(estimated, job.machine);
    return stream_job({planning, nullptr, &planning, &tap, &job.path, job.path.subpaths.size(),
                       [&estimate, &tap]() -> std::optional<std::uint64_t> {
                           const StreamPlanTap::Planned p = tap.planned();
                           return estimate.total_ticks(p.mm, p.ticks);
                       }},
                      job.machine, o, journal, journal_path, nullptr, channel);
}

// The events' file, opened before anything is planned or sent (so a bad path costs nothing),
// and with --mqtt the broker, reached before anything is planned too (exit 3 when it cannot
// be): the events also go there.
EventChannel open_events(const StreamCommandOptions& o,
                         std::unique_ptr<serve::StreamReporter>& reporter) {
    EventChannel channel;
    channel.progress_hz = o.events_rate;
    if (!o.events.empty()) channel.writer = NdjsonWriter::open(o.events);
    if (!o.mqtt.empty()) {
        if (o.name.empty()) throw std::invalid_argument("stream: --mqtt needs --name NAME");
        serve::check_machine_name(o.name);
        const MqttUrl url = parse_mqtt_url(o.mqtt);
        // A resumed job names its machine and device in its journal.
        std::string machine_file = o.machine, target = o.stream.target;
        if (!o.resume.empty()) {
            const JobJournal j = read_journal(o.resume);
            machine_file = j.machine;
            target = j.target;
        }
        if (machine_file.empty())
            throw std::invalid_argument("stream: --mqtt needs --machine (or --resume JOURNAL)");
        const std::string absolute = std::filesystem::absolute(machine_file).string();
        // Ours before the machine shows online: a signal sent on seeing it must not be lost (a
        // script's background job starts with SIGINT ignored). The job then acts on it as on
        // any Ctrl-C.
        std::signal(SIGINT, on_stream_signal);
        std::signal(SIGTERM, on_stream_signal);
        reporter = std::make_unique<serve::StreamReporter>(
            serve::MqttLink{url, o.name, "any"}, load_machine_profile(absolute),
            serve::OperatorTarget{serve::self_executable(), absolute, target,
                                  std::filesystem::current_path().string()},
            absolute);
        reporter->start();
        channel.tap = [r = reporter.get()](const std::string& line) { r->event(line); };
    }
    return channel;
}

}  // namespace

int run_stream(const StreamCommandOptions& o) {
    std::unique_ptr<serve::StreamReporter> reporter;
    const EventChannel channel = open_events(o, reporter);
    if (!o.resume.empty()) {
        if (o.lead_in || o.no_lead_in)
            throw std::invalid_argument(std::string("--resume: ") +
                                        (o.lead_in ? "--lead-in" : "--no-lead-in") +
                                        " does not apply (the resume plans its own move)");
        return run_resume(o, channel);
    }
    if (o.path.file.empty())
        throw std::invalid_argument("stream: FILE is required (or --resume JOURNAL)");
    if (o.machine.empty())
        throw std::invalid_argument("stream: --machine is required (or --resume JOURNAL)");
    if (o.stream.target.empty())
        throw std::invalid_argument("stream: --target is required (or --resume JOURNAL)");
    const std::string& url = o.stream.target;
    // From here a Ctrl-C is ours: one during planning ends the command before anything is sent
    // (a background job's SIGINT, ignored by default, would otherwise be lost).
    std::signal(SIGINT, on_stream_signal);
    std::signal(SIGTERM, on_stream_signal);
    if (url.rfind("modbus-tcp://", 0) != 0 && url.rfind("modbus-rtu://", 0) != 0 &&
        url.rfind("can://", 0) != 0) {
        throw std::invalid_argument(
            "bad target URL '" + url +
            "': unknown scheme (want modbus-tcp://, modbus-rtu:// or can://)");
    }
    const std::string journal_path =
        o.no_journal ? "" : (o.journal.empty() ? default_journal_path(o.path.file) : o.journal);
    if (!o.replace_journal && !journal_path.empty()) refuse_unfinished_journal(journal_path);
    std::vector<double> rest_mm;
    // The path order starts where the device rests (its first subpath is the one nearest to
    // it), so the drawing begins where the pen is, and the lead-in goes from there to it.
    JobRequest path = o.path;
    const bool cia402 =
        url.rfind("can://", 0) == 0 && url.find("protocol=cia402") != std::string::npos;
    if (cia402 && o.lead_in) {
        throw std::invalid_argument(
            "--lead-in: CiA 402 drives must stand at the drawing's first point (docs/cia402.md); "
            "the lead-in "
            "is for Modbus and native CAN targets");
    }
    const bool lead_in = !cia402 && !o.no_lead_in;
    const bool order_from_rest = !cia402 && !path.keep_order && path.order_start.empty();
    if (lead_in || order_from_rest) {
        const MachineProfile machine = load_machine_profile(o.machine);
        std::vector<Lsb> rest;
        if (o.stream.target.rfind("can://", 0) == 0) {
            const CanTarget t = parse_can_target(o.stream.target);
            hal::SocketCanBus bus(t.interface_name);
            CanStreamOptions c;
            c.node = t.node;
            c.name = o.stream.target;
            c.ack_timeout_ms = std::min(o.stream.response_timeout_ms, 100u);
            c.link_timeout_seconds = o.stream.link_timeout_seconds;
            rest = can_rest_position(machine, bus, c);
        } else {
            rest = modbus_rest_position(machine, o.stream);
        }
        for (const Lsb p : rest) rest_mm.push_back(p * machine.mm_per_lsb);
        if (!lead_in) {
            for (std::size_t a = 0; a < rest_mm.size(); ++a) {
                path.order_start += (a ? "," : "") + exact_decimal(rest_mm[a]);
            }
        }
    }
    JobJournal journal;
    journal.target = url;
    journal.machine = std::filesystem::absolute(o.machine).string();
    journal.drawing = path_display_name(o.path.file);
    const JobFilesGuard files(journal_path);
    if (cia402 || o.plan_first) {
        const PlannedJob planned = plan_job(path, o.machine, lead_in ? &rest_mm : nullptr);
        if (lead_in) print_lead_in(planned, rest_mm);
        if (g_interrupts.load() > 0) {
            std::printf("interrupted   while planning: nothing was sent to the device\n");
            return kExitInterrupted;
        }
        if (cia402) {
            std::signal(SIGINT, SIG_DFL);  // CiA 402 streams have no hold: Ctrl-C ends the process
            std::signal(SIGTERM, SIG_DFL);
            // CiA 402 drives take one setpoint per cycle from the host: no device queue to hold.
            return stream_cia402(planned, url, channel, path_display_name(o.path.file));
        }
        journal.pauses = pause_descriptions(planned.path, planned.plan);
        const JobSpans job = job_from_plan(planned.plan);
        PlanSupply supply(job.plan);
        return stream_job({supply, &job, nullptr, nullptr, nullptr, job.subpaths, {}},
                          planned.machine, o, journal, journal_path, nullptr, channel);
    }
    if (!journal_path.empty()) {
        // The plan is made as the stream goes: keep what plans it again after a host crash.
        const JobRecipe recipe = save_job_recipe(
            path, o.machine, lead_in ? std::optional<std::vector<double>>(rest_mm) : std::nullopt,
            std::filesystem::absolute(journal_path + ".input").string());
        journal.replan = job_recipe_json(recipe);
    }
    const PlannedJob prepared = prepare_streamed_job(path, o.machine, lead_in ? &rest_mm : nullptr);
    if (lead_in) print_lead_in(prepared, rest_mm);
    return stream_while_planning(prepared, o, journal, journal_path, channel);
}

}  // namespace pathstream::host
