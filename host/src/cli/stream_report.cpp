// What a stream prints of itself: the progress bar's view, the report of a finished job per
// bus, where an interrupted job stopped, the lead-in, and what follows each programmed pause.
#include <cstdio>
#include <optional>
#include <string>

#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "stream_job.hpp"

namespace pathstream::host {
namespace {

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

}  // namespace

// What comes after a programmed pause that subpath `subpath` follows: the next layer's name
// where the layer changes, else the subpath and where it is in the file.
std::string pause_description(const Path& path, std::size_t subpath) {
    const Subpath& s = path.subpaths.at(subpath);
    const bool new_layer =
        !path.layers.empty() && (subpath == 0 || path.subpaths[subpath - 1].layer != s.layer);
    if (!s.pause_note.empty()) return s.pause_note;
    if (new_layer) return "layer \"" + path.layers.at(s.layer).name + "\"";
    return "subpath " + std::to_string(subpath + 1) +
           (s.location.line > 0 ? " (line " + std::to_string(s.location.line) + ")" : "");
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
                end.interrupted == 1 && s.state == device::DeviceState::kHolding
                    ? "holds at rest (the rest of the job queued)"
                : s.state == device::DeviceState::kIdle ? "stopped and is idle (queue dropped)"
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
    const bool moved =
        job.segments.empty()
            ? job.lead_in.has_value()
            : !job.segments.front().pen_down && job.segments.size() > 1 &&
                  job.segments.front().p[0] == PathPoint(rest_mm.begin(), rest_mm.end());
    if (moved) {
        std::printf("lead-in       pen up from where the device rests,%s, to the drawing's start\n",
                    at.c_str());
    } else {
        std::printf("start         the device rests at the drawing's start,%s: no lead-in\n",
                    at.c_str());
    }
}

}  // namespace pathstream::host
