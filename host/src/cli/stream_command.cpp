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
#include "pathstream/host/planning_thread.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/host/resume_decision.hpp"
#include "pathstream/host/resume_path.hpp"
#include "pathstream/host/span_supply.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/input_error.hpp"
#include "plan_command.hpp"
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

// What a stream ended with, whichever bus carried it.
struct StreamEnd {
    int interrupted = 0;
    DeviceSnapshot status;
    std::uint32_t job = 0;
    bool stopped_elsewhere = false;  // interrupted 2 by another client's stop
};

// What comes after a programmed pause that subpath `subpath` follows: the next layer's name
// where the layer changes, else the subpath and where it is in the file.
std::string pause_description(const Path& path, std::size_t subpath) {
    const Subpath& s = path.subpaths.at(subpath);
    const bool new_layer =
        !path.layers.empty() && (subpath == 0 || path.subpaths[subpath - 1].layer != s.layer);
    if (new_layer) return "layer \"" + path.layers.at(s.layer).name + "\"";
    return "subpath " + std::to_string(subpath + 1) +
           (s.location.line > 0 ? " (line " + std::to_string(s.location.line) + ")" : "");
}

// Where a span sits in the drawing: for the report of where an interrupted job stopped.
struct SpanPlace {
    std::int64_t origin = 0;  // index in the drawing's plan; -1: a re-entry span
    std::size_t subpath = 0;
    std::uint64_t drawing_tick = 0;  // the drawing's tick at its start
};

// The whole drawing's counts, known once planning ended.
struct DrawingTotals {
    std::size_t spans = 0;
    std::size_t subpaths = 0;
    std::uint64_t ticks = 0;
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

// The progress bar's fraction, ETA and detail: the fraction of the whole drawing and the motion
// left (estimated while planning goes on, marked "~"), then the queue level, how far planning
// got while it runs, and where the job is.
struct BarView {
    double fraction = 0;
    ProgressEta eta;
    std::string detail;
};
BarView bar_view(std::uint64_t ticks, std::optional<std::uint64_t> total, double queued,
                 const JobEvents& events, const PlanningThread* planning, double tick_hz) {
    char text[96];
    BarView v;
    if (const std::optional<JobEvents::Progress> p = events.progress(ticks)) {
        v.fraction = p->fraction;
        v.eta = {static_cast<double>(p->ticks_left) / tick_hz, p->estimated};
    } else if (total) {
        v.fraction = *total > 0 ? static_cast<double>(ticks) / static_cast<double>(*total) : 1.0;
    }
    if (total || planning == nullptr || planning->finished()) {
        std::snprintf(text, sizeof text, "queue %.2f s", queued);
    } else {
        std::snprintf(text, sizeof text, "planning %.0f %%, queue %.2f s",
                      100 * planning->fraction(), queued);
    }
    const std::string status = events.status_text();
    v.detail = status.empty() ? std::string(text) : std::string(text) + ", " + status;
    return v;
}

StreamEnd stream_over_can(SpanSupply& supply, const MachineProfile& machine,
                          const StreamCommandOptions& o, const StreamObserver& observer,
                          const HeldJob* held, const JobEvents& events,
                          const PlanningThread* planning) {
    const CanTarget t = parse_can_target(o.stream.target);
    hal::SocketCanBus bus(t.interface_name);
    CanStreamOptions c;
    c.node = t.node;
    c.name = o.stream.target;
    c.lead_seconds = o.stream.lead_seconds;
    c.ack_timeout_ms = std::min(o.stream.response_timeout_ms, 100u);
    c.link_timeout_seconds = o.stream.link_timeout_seconds;
    c.interrupt = o.stream.interrupt;
    c.observer = observer;
    c.held = held;
    CanStreamReport r;
    {
        ProgressBar bar("streaming");
        r = stream_can(supply, machine, bus, c,
                       [&](std::uint64_t ticks, std::optional<std::uint64_t> total, double queued) {
                           const BarView v =
                               bar_view(ticks, total, queued, events, planning, machine.tick_hz);
                           bar.update(v.fraction, v.detail, v.eta);
                       });
    }
    if (r.interrupted != 0) return {r.interrupted, r.final_status, r.job, r.stopped_elsewhere};
    const double motion = static_cast<double>(r.ticks_executed) / machine.tick_hz;
    std::printf("streamed      %s (native CAN protocol, node %u)\n", o.stream.target.c_str(),
                unsigned(t.node));
    std::printf(
        "executed      %llu ticks (%.3f s of motion), %llu spans in %llu batches, last span %u\n",
        static_cast<unsigned long long>(r.ticks_executed), motion,
        static_cast<unsigned long long>(r.spans_sent), static_cast<unsigned long long>(r.batches),
        r.last_completed);
    std::printf("job           %u finished: the device is idle at the drawing's end point\n",
                r.job);
    std::printf(
        "bus           %llu frames sent, %llu received, %llu retransmitted batches, %llu timeouts;"
        " %.1f kbit/s worst case (%.2f %% of 1 Mbit/s)\n",
        static_cast<unsigned long long>(r.frames_sent),
        static_cast<unsigned long long>(r.frames_received),
        static_cast<unsigned long long>(r.retransmissions),
        static_cast<unsigned long long>(r.timeouts),
        static_cast<double>(r.bits_sent + r.bits_received) / motion / 1e3,
        static_cast<double>(r.bits_sent + r.bits_received) / motion / 1e4);
    std::printf("device        %u underruns, %u duplicate batches acknowledged; wall time %.2f s\n",
                r.underruns, r.duplicates, r.wall_seconds);
    return {0, r.final_status, r.job};
}

StreamEnd stream_over_modbus(SpanSupply& supply, const MachineProfile& machine,
                             const StreamCommandOptions& o, const StreamObserver& observer,
                             const HeldJob* held, const JobEvents& events,
                             const PlanningThread* planning) {
    StreamOptions options = o.stream;
    options.observer = observer;
    options.held = held;
    StreamReport r;
    {
        ProgressBar bar("streaming");
        r = stream_modbus(
            supply, machine, options,
            [&](std::uint64_t ticks, std::optional<std::uint64_t> total, double queued) {
                const BarView v = bar_view(ticks, total, queued, events, planning, machine.tick_hz);
                bar.update(v.fraction, v.detail, v.eta);
            });
    }
    if (r.interrupted != 0) return {r.interrupted, r.final_status, r.job, r.stopped_elsewhere};
    std::printf("streamed      %s\n", o.stream.target.c_str());
    std::printf(
        "executed      %llu ticks (%.3f s of motion), %llu spans in %llu batches, last span %u\n",
        static_cast<unsigned long long>(r.ticks_executed),
        static_cast<double>(r.ticks_executed) / machine.tick_hz,
        static_cast<unsigned long long>(r.spans_sent), static_cast<unsigned long long>(r.batches),
        r.last_completed);
    std::printf("job           %u finished: the device is idle at the drawing's end point\n",
                r.job);
    std::printf("final point  ");
    for (std::size_t a = 0; a < machine.axes.size(); ++a) {
        std::printf(" %s %.4f mm", machine.axes[a].name.c_str(),
                    r.final_position[a] * machine.mm_per_lsb);
    }
    std::printf(
        "\nlink          %llu transactions, %llu retries, %llu reconnects, %llu bytes sent, %llu "
        "received"
        " (%.0f B per s of motion)\n",
        static_cast<unsigned long long>(r.transactions), static_cast<unsigned long long>(r.retries),
        static_cast<unsigned long long>(r.reconnects),
        static_cast<unsigned long long>(r.bytes_sent),
        static_cast<unsigned long long>(r.bytes_received),
        (r.bytes_sent + r.bytes_received) /
            (static_cast<double>(r.ticks_executed) / machine.tick_hz));
    std::printf("device        %u underruns, %u duplicate batches acknowledged; wall time %.2f s\n",
                r.underruns, r.duplicates, r.wall_seconds);
    return {0, r.final_status, r.job};
}

// Where an interrupted job stopped, in the drawing's terms, and how to go on. `next`: the
// first span of the job not executed to its end (its place, when known); `totals`: the
// drawing's, when planning got to its end; `resumable`: the journal can resume it.
void print_interrupted(const StreamEnd& end, std::optional<SpanPlace> next,
                       std::optional<DrawingTotals> totals, const MachineProfile& machine,
                       const std::string& journal, bool resumable) {
    const DeviceSnapshot& s = end.status;
    std::printf("interrupted   the device %s at",
                end.interrupted == 1 && s.state == device::DeviceState::kHolding ? "holds at rest (the rest of the job queued)"
                : s.state == device::DeviceState::kIdle                       ? "stopped and is idle (queue dropped)"
                                                     : device_state_name(s.state));
    for (std::size_t a = 0; a < machine.axes.size(); ++a) {
        std::printf(" %s %.4f mm", machine.axes[a].name.c_str(),
                    s.position[a] * machine.mm_per_lsb);
    }
    std::printf(", pen up\n");
    if (next && totals) {
        std::printf(
            "              stopped before drawing span %lld of %zu (subpath %zu of %zu, tick %llu "
            "of %llu)\n",
            static_cast<long long>(next->origin) + 1, totals->spans, next->subpath + 1,
            totals->subpaths, static_cast<unsigned long long>(next->drawing_tick),
            static_cast<unsigned long long>(totals->ticks));
    } else if (next) {
        std::printf(
            "              stopped before drawing span %lld (subpath %zu, tick %llu; planning did "
            "not finish)\n",
            static_cast<long long>(next->origin) + 1, next->subpath + 1,
            static_cast<unsigned long long>(next->drawing_tick));
    }
    if (journal.empty()) {
        std::printf("resume        not possible: --no-journal\n");
    } else if (!resumable) {
        std::printf(
            "resume        not possible: planning did not finish, the journal has no plan to go on "
            "from\n");
    } else {
        std::printf("resume with   pathstream stream --resume %s\n", journal.c_str());
    }
}

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

// Says where the job starts: at the device's rest position, or after a pen-up lead-in from it
// (prepare_job put one first when the two differ on the LSB grid).
void print_lead_in(const PlannedJob& job, const std::vector<double>& rest_mm) {
    std::string at;
    char value[48];
    for (std::size_t a = 0; a < rest_mm.size() && a < job.machine.axes.size(); ++a) {
        std::snprintf(value, sizeof value, " %s %.4f mm", job.machine.axes[a].name.c_str(),
                      rest_mm[a]);
        at += value;
    }
    const bool moved = !job.segments.empty() && !job.segments.front().pen_down &&
                       job.segments.size() > 1 &&
                       job.segments.front().p[0] == PathPoint(rest_mm.begin(), rest_mm.end());
    if (moved) {
        std::printf("lead-in       pen up from where the device rests,%s, to the drawing's start\n",
                    at.c_str());
    } else {
        std::printf("start         the device rests at the drawing's start,%s: no lead-in\n",
                    at.c_str());
    }
}

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
        std::fprintf(
            stderr,
            "\npathstream: paused for a pen change, %s next: %s `pathstream ctl %s resume`\n",
            next.c_str(), terminal ? "press Enter to go on, or" : "go on with", target.c_str());
        events.pause(index, next);
    };
    if (terminal) interrupt.resume_requested = enter_pressed;
}

// What stream_job streams: the spans and what is known of the whole job.
struct JobToStream {
    SpanSupply& supply;
    // The job held in memory (a resume, --plan-first): its spans file is written before the
    // stream, its totals known. Null: a first job planned as it streams.
    const JobSpans* spans = nullptr;
    // The planner feeding `supply` and its tap (the spans file), for a job planned as it
    // streams; `path` describes its pauses.
    PlanningThread* planning = nullptr;
    const StreamPlanTap* tap = nullptr;
    const Path* path = nullptr;
    std::size_t subpaths = 0;  // of the whole drawing
    // The job's ticks estimated while planning goes on (JobEvents::set_progress_basis).
    std::function<std::optional<std::uint64_t>()> estimate;
};

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
    const JobSpans resumed = resume_from(job, first, rest, device_limits(machine));
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
    VectorSegmentSource source(job.segments);
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
    const JobEstimate estimate(job.segments, job.machine);
    return stream_job({planning, nullptr, &planning, &tap, &job.path, job.path.subpaths.size(),
                       [&estimate, &tap]() -> std::optional<std::uint64_t> {
                           const StreamPlanTap::Planned p = tap.planned();
                           return estimate.total_ticks(p.mm, p.ticks);
                       }},
                      job.machine, o, journal, journal_path, nullptr, channel);
}

// The events' file, opened before anything is planned or sent (so a bad path costs nothing).
EventChannel open_events(const StreamCommandOptions& o) {
    EventChannel channel;
    channel.progress_hz = o.events_rate;
    if (!o.events.empty()) channel.writer = NdjsonWriter::open(o.events);
    return channel;
}

}  // namespace

int run_stream(const StreamCommandOptions& o) {
    const EventChannel channel = open_events(o);
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
    const PlannedJob prepared = prepare_job(path, o.machine, lead_in ? &rest_mm : nullptr);
    if (lead_in) print_lead_in(prepared, rest_mm);
    return stream_while_planning(prepared, o, journal, journal_path, channel);
}

}  // namespace pathstream::host
