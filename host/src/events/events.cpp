// Machine-readable events: the NDJSON writer and a job's events (docs/events.md).
#include "pathstream/host/events.hpp"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <ctime>
#include <iostream>
#include <stdexcept>

#include "pathstream/device/device_state.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/machine/device_setup.hpp"

namespace pathstream::host {
namespace {

constexpr device::DeviceState kRunning = device::DeviceState::kRunning;
constexpr device::DeviceState kFault = device::DeviceState::kFault;

// Times and lengths to a fixed resolution, so lines stay short and compare as printed.
double rounded(double value, double per_unit) {
    return std::round(value * per_unit) / per_unit;
}

// The standard output as a file of its own, with descriptor 1 moved to standard error: the
// events own the standard output and every other line printed lands on standard error.
std::FILE* take_standard_output() {
    std::cout.flush();
    std::fflush(stdout);
    const int fd = dup(STDOUT_FILENO);
    if (fd < 0 || dup2(STDERR_FILENO, STDOUT_FILENO) < 0) {
        throw std::runtime_error(std::string("--events -: cannot take over the standard output: ") +
                                 std::strerror(errno));
    }
    std::FILE* f = fdopen(fd, "w");
    if (f == nullptr) throw std::runtime_error(std::string("--events -: ") + std::strerror(errno));
    return f;
}

}  // namespace

NdjsonWriter::NdjsonWriter(std::FILE* file) : NdjsonWriter(file, false) {}

NdjsonWriter::NdjsonWriter(std::FILE* file, bool owned) : file_(file), owned_(owned) {}

std::unique_ptr<NdjsonWriter> NdjsonWriter::open(const std::string& path) {
    if (path == "-")
        return std::unique_ptr<NdjsonWriter>(new NdjsonWriter(take_standard_output(), true));
    std::FILE* f = std::fopen(path.c_str(), "w");
    if (f == nullptr) {
        throw std::runtime_error("--events: cannot write '" + path + "': " + std::strerror(errno));
    }
    return std::unique_ptr<NdjsonWriter>(new NdjsonWriter(f, true));
}

NdjsonWriter::~NdjsonWriter() {
    if (owned_) std::fclose(file_);
}

void NdjsonWriter::write(const EventJson& object) {
    std::string line = object.dump(-1, ' ', false, EventJson::error_handler_t::replace);
    line += '\n';
    std::fwrite(line.data(), 1, line.size(), file_);
    std::fflush(file_);
}

JobEvents::JobEvents(const EventChannel& channel, const MachineProfile& machine, JobInfo info)
    : channel_(channel), machine_(machine), info_(std::move(info)) {}

JobEvents::JobEvents(const EventChannel& channel, const Plan& plan, const MachineProfile& machine,
                     JobInfo info)
    : JobEvents(channel, machine, std::move(info)) {
    for (const CoreSpan& s : plan.spans) add_span(s);
    set_totals(plan.total_ticks, plan.spans.size(), plan.pauses.size());
}

void JobEvents::add_span(const CoreSpan& span) {
    marks_.push_back({ticks_added_, span.subpath, span.pen_down});
    ++spans_added_;
    ticks_added_ += span.ticks;
}

void JobEvents::set_totals(std::uint64_t ticks, std::size_t spans, std::size_t pauses) {
    total_ticks_ = ticks;
    total_spans_ = spans;
    total_pauses_ = pauses;
}

// Ticks of the spans before `span` (clamped to the spans added; never below the spans
// already dropped, which the samples have passed).
std::uint64_t JobEvents::ticks_before(std::size_t span) const {
    if (span >= spans_added_) return ticks_added_;
    return marks_.at(span - std::min(span, marks_base_)).ticks_before;
}

EventJson JobEvents::total_json(const std::optional<std::uint64_t>& value) const {
    return value ? EventJson(*value) : EventJson(nullptr);
}

// Seconds since the command started, to the microsecond.
double JobEvents::now() const {
    const double t =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - channel_.start).count();
    return rounded(t, 1e6);
}

// An event's common fields: its type, `t`, and for a simulated run the simulated time.
EventJson JobEvents::event(const char* type) const {
    EventJson e;
    e["event"] = type;
    e["t"] = now();
    if (sim_seconds_) e["sim_t"] = rounded(*sim_seconds_, 1e6);
    return e;
}

void JobEvents::emit(const EventJson& e) const {
    if (channel_.writer) channel_.writer->write(e);
    if (channel_.tap) channel_.tap(e.dump());
}

void JobEvents::start(std::optional<std::uint32_t> job) {
    if (started_event_) return;
    started_event_ = true;
    job_ = job;
    EventJson e = event("job_start");
    start_t_ = e["t"].get<double>();
    e["command"] = info_.command;
    e["drawing"] = info_.drawing;
    e["target"] = info_.target;
    e["job"] = job ? EventJson(*job) : EventJson(nullptr);
    e["plan_ticks"] = total_json(total_ticks_);
    e["duration_s"] = total_ticks_
                          ? EventJson(static_cast<double>(*total_ticks_) / machine_.tick_hz)
                          : EventJson(nullptr);
    e["spans"] = total_json(total_spans_);
    e["subpaths"] = info_.subpaths;
    e["tick_hz"] = machine_.tick_hz;
    e["mm_per_lsb"] = machine_.mm_per_lsb;
    EventJson axes = EventJson::array();
    for (const AxisLimits& a : machine_.axes) axes.push_back(a.name);
    e["axes"] = axes;
    emit(e);
}

void JobEvents::sample(const JobSample& s) {
    sim_seconds_ = s.sim_seconds;
    pen_output_ = s.pen_output;
    if (first_sample_) {
        // A held job continues: the spans before this one were entered in an earlier run.
        entered_ = static_cast<long long>(s.next_span) - 1;
        underruns_base_ = underruns_ = s.underruns.value_or(0);
        first_sample_ = false;
    }
    on_requests(s);
    on_state(s);
    on_underruns(s);
    ticks_ = s.ticks;
    if (s.started) running_seen_ = true;
    if (!running_seen_) return;
    enter_spans(s);
    on_progress(s);
}

// A state event at every change (and a fault event when the state is fault).
void JobEvents::on_state(const JobSample& s) {
    if (!s.state) return;
    const bool fault = *s.state == kFault;
    const bool new_fault = fault && (state_ != kFault || s.fault_code != fault_code_);
    if (state_ == s.state && !new_fault) return;
    EventJson e = event("state");
    e["state"] = device_state_name(*s.state);
    e["code"] = static_cast<unsigned>(*s.state);
    e["was"] = state_ ? EventJson(device_state_name(*state_)) : EventJson(nullptr);
    if (fault) e["fault"] = fault_text(s.fault_code);
    emit(e);
    if (new_fault) {
        EventJson f = event("fault");
        f["code"] = s.fault_code;
        f["name"] = fault_text(s.fault_code);
        f["ticks"] = s.ticks;
        emit(f);
    }
    state_ = s.state;
    fault_code_ = s.fault_code;
}

// hold and stop, once each, when the interrupt handling asked the device for them.
void JobEvents::on_requests(const JobSample& s) {
    if (s.hold_requested && !hold_) {
        EventJson e = event("hold");
        e["ticks"] = s.ticks;
        emit(e);
        hold_ = true;
    }
    if (s.stop_requested && !stop_) {
        EventJson e = event("stop");
        e["ticks"] = s.ticks;
        emit(e);
        stop_ = true;
    }
}

// An underrun event whenever the device's counter grew since the last sample.
void JobEvents::on_underruns(const JobSample& s) {
    if (!s.underruns || *s.underruns <= underruns_) return;
    underruns_ = *s.underruns;
    EventJson e = event("underrun");
    e["count"] = underruns_ - underruns_base_;
    e["device_count"] = underruns_;
    e["ticks"] = s.ticks;
    emit(e);
}

// subpath and pen events for every span the device entered since the last sample, in order:
// a sample may come after several short spans, and none of their changes may be lost.
void JobEvents::enter_spans(const JobSample& s) {
    if (spans_added_ == 0) return;
    const long long last = static_cast<long long>(std::min(s.next_span, spans_added_ - 1));
    for (long long k = entered_ + 1; k <= last; ++k) {
        const SpanMark& span = marks_.at(static_cast<std::size_t>(k) - marks_base_);
        if (!subpath_ || *subpath_ != span.subpath) {
            subpath_ = span.subpath;
            EventJson e = event("subpath");
            e["n"] = span.subpath + 1;
            e["of"] = info_.subpaths;
            e["span"] = k;
            emit(e);
        }
        if (span.pen_down != pen_down_) {
            pen_down_ = span.pen_down;
            EventJson e = event("pen");
            e["down"] = pen_down_;
            e["span"] = k;
            emit(e);
        }
    }
    entered_ = std::max(entered_, last);
    // The samples only go forward: spans before the last entered one are not looked at again.
    while (entered_ > 0 && marks_base_ < static_cast<std::size_t>(entered_) && !marks_.empty()) {
        marks_.pop_front();
        ++marks_base_;
    }
}

void JobEvents::set_progress_basis(std::uint64_t before,
                                   std::function<std::optional<std::uint64_t>()> estimate) {
    ticks_before_job_ = before;
    estimate_ = std::move(estimate);
}

std::optional<JobEvents::Progress> JobEvents::progress(std::uint64_t ticks) const {
    std::optional<std::uint64_t> total = total_ticks_;
    const bool estimated = !total && estimate_;
    if (estimated) total = estimate_();
    if (!total) return std::nullopt;
    Progress p;
    p.estimated = estimated;
    // An estimate may fall short of what already ran: never past the end before the end.
    const std::uint64_t job = estimated ? std::max(*total, ticks + 1) : *total;
    const std::uint64_t whole = ticks_before_job_ + job;
    p.fraction = whole > 0
                     ? std::min(1.0, static_cast<double>(ticks_before_job_ + std::min(ticks, job)) /
                                         static_cast<double>(whole))
                     : 1.0;
    p.ticks_left = job - std::min(ticks, job);
    return p;
}

// A progress event at most progress_hz times a second (simulated seconds for sim).
void JobEvents::on_progress(const JobSample& s) {
    EventJson e = event("progress");
    const double clock = s.sim_seconds ? e["sim_t"].get<double>() : e["t"].get<double>();
    if (last_progress_ && clock - *last_progress_ < 1.0 / channel_.progress_hz) return;
    last_progress_ = clock;
    const std::optional<Progress> p = progress(s.ticks);
    // Without totals or an estimate (still planning): how far the job goes is not known yet.
    e["fraction"] = p ? EventJson(rounded(p->fraction, 1e6)) : EventJson(nullptr);
    e["ticks"] = s.ticks;
    e["plan_ticks"] = total_json(total_ticks_);
    e["eta_s"] = p ? EventJson(rounded(static_cast<double>(p->ticks_left) / machine_.tick_hz, 1e6))
                   : EventJson(nullptr);
    e["estimated"] = p && p->estimated;
    e["queue_s"] = rounded(static_cast<double>(s.queued_ticks) / machine_.tick_hz, 1e6);
    e["queue_spans"] = s.queued_spans ? EventJson(*s.queued_spans) : EventJson(nullptr);
    e["position_mm"] = position_json(s.position);
    emit(e);
}

EventJson JobEvents::position_json(const Lsb* position) const {
    EventJson p = EventJson::object();
    for (std::size_t a = 0; a < machine_.axes.size() && a < kMaxAxes; ++a) {
        p[machine_.axes[a].name] = rounded(position[a] * machine_.mm_per_lsb, 1e6);
    }
    return p;
}

void JobEvents::trace(const StreamTrace& t) {
    start(t.job);
    const DeviceSnapshot& d = t.status;
    const std::size_t spans = spans_added_;
    // Sequence numbers: span i of the job is sequence job + i.
    const auto index_after = [&](std::uint32_t sequence) -> std::size_t {
        if (t.job == 0 || sequence + 1 < t.job) return 0;
        return std::min<std::size_t>(sequence + 1 - t.job, spans);
    };
    JobSample s;
    s.state = d.state;
    s.fault_code = d.fault_code;
    s.next_span = index_after(d.last_completed);
    if (!have_base_) {
        // The device counts path ticks of every job: the job's tick 0 is where it stood then.
        tick_base_ = d.ticks_executed - static_cast<std::uint32_t>(ticks_before(s.next_span));
        first_ticks_ = ticks_before(s.next_span);
        have_base_ = true;
    }
    s.ticks = static_cast<std::uint32_t>(d.ticks_executed - tick_base_);
    if (total_ticks_) s.ticks = std::min(s.ticks, *total_ticks_);
    // Running, or it ran between two reads (a short job, or an underrun's hold in between).
    s.started = d.state == kRunning || s.ticks > first_ticks_;
    const std::uint64_t sent = ticks_before(index_after(t.acknowledged));
    s.queued_ticks = sent > s.ticks ? sent - s.ticks : 0;
    s.queued_spans = d.queued;
    s.underruns = d.underruns;
    std::copy(d.position, d.position + kMaxAxes, s.position);
    s.hold_requested = t.hold_requested;
    s.stop_requested = t.stop_requested;
    s.pen_output = d.pen_down();
    sample(s);
}

void JobEvents::pause(std::size_t index, const std::string& next) {
    start(job_);
    EventJson e = event("pause");
    e["pause"] = index + 1;
    e["pauses"] = total_json(total_pauses_);
    e["ticks"] = ticks_;
    e["next"] = next;
    emit(e);
}

void JobEvents::end(const std::string& outcome, const std::string& error,
                    std::optional<std::uint64_t> ticks) {
    if (ended_) return;
    start(job_);
    ended_ = true;
    EventJson e = event("job_end");
    e["outcome"] = outcome;
    e["job"] = job_ ? EventJson(*job_) : EventJson(nullptr);
    e["ticks"] = ticks.value_or(ticks_);
    e["plan_ticks"] = total_json(total_ticks_);
    e["wall_s"] = rounded(e["t"].get<double>() - start_t_, 1e6);
    if (!error.empty()) e["error"] = error;
    emit(e);
}

std::string JobEvents::status_text() const {
    std::string text;
    const auto add = [&](const std::string& part) { text += (text.empty() ? "" : ", ") + part; };
    if (subpath_)
        add("subpath " + std::to_string(*subpath_ + 1) + "/" + std::to_string(info_.subpaths));
    if (running_seen_) add(pen_output_.value_or(pen_down_) ? "pen down" : "pen up");
    if (state_) add(device_state_name(*state_));
    return text;
}

}  // namespace pathstream::host
