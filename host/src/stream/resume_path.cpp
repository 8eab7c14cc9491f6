// The move back onto the drawing that a resume streams: from where the device rests, a
// re-entry (the core's plan_reentry, or plan_jerk_reentry under a jerk limit) and a pen-down
// approach to the first span not executed, then the job's own spans from there.
#include "pathstream/host/resume_path.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

#include "pathstream/device/jerk_moves.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/stop_spans.hpp"
#include "pathstream/machine/core_span_conversion.hpp"

namespace pathstream::host {
namespace {

// The device's limits as the core's functions take them.
template <unsigned Axes>
device::MotionLimits<Axes> motion_limits(const DeviceLimitsLsb& l) {
    device::MotionLimits<Axes> limits;
    limits.tick_hz = l.tick_hz;
    limits.pen_down_ticks = l.pen_down_ticks;
    for (unsigned a = 0; a < Axes; ++a) {
        limits.axis[a].max_velocity = l.max_velocity[a];
        limits.axis[a].max_acceleration = l.max_acceleration[a];
        if (l.max_jerk.size() == Axes) limits.axis[a].max_jerk = l.max_jerk[a];
    }
    return limits;
}

// The core's plan_reentry for a run-time axis count; `out` keeps its subpath and pen.
Status reentry(const std::vector<Lsb>& from, const std::vector<std::int32_t>& to,
               const std::vector<std::int32_t>& tangent, std::uint32_t ticks,
               const DeviceLimitsLsb& l, CoreSpan& out) {
    return with_axes(from.size(), [&](auto tag) {
        constexpr unsigned kAxes = decltype(tag)::value;
        Lsb f[kAxes], t[kAxes];
        std::int32_t g[kAxes];
        for (unsigned a = 0; a < kAxes; ++a) {
            f[a] = from[a];
            t[a] = to[a];
            g[a] = tangent[a];
        }
        Span<kAxes> span;
        const Status s = device::plan_reentry(f, t, g, ticks, motion_limits<kAxes>(l), span);
        if (s == Status::kOk) out = from_core_span(span, out.subpath, out.pen_down, out.machine);
        return s;
    });
}

// Under a jerk limit, onto `target`'s start (its velocity and start acceleration): the
// approach, when `approach_ticks` > 0 (a span of at least that many ticks ending there and
// starting at about no acceleration: jerk_moves.hpp's ramp, pen down), and the re-entry from rest
// at `from` onto it (plan_jerk_reentry, pen up). `out`: the re-entry spans, then the approach.
Status jerk_reentry(const std::vector<Lsb>& from, const CoreSpan& target,
                    std::uint32_t approach_ticks, const DeviceLimitsLsb& l,
                    std::vector<CoreSpan>& out) {
    return with_axes(from.size(), [&](auto tag) {
        constexpr unsigned kAxes = decltype(tag)::value;
        const device::MotionLimits<kAxes> limits = motion_limits<kAxes>(l);
        Lsb f[kAxes], t[kAxes];
        std::int32_t g[kAxes];
        device::TickAcceleration acc[kAxes];
        for (unsigned a = 0; a < kAxes; ++a) {
            const auto& c = target.control[a];
            f[a] = from[a];
            t[a] = c[0];
            g[a] = c[2];
            // The target's start acceleration: (6 (P1 - P0) - 4 T0 - 2 T1) / n^2 LSB/tick^2.
            acc[a] = device::TickAcceleration{
                6 * (static_cast<std::int64_t>(c[1]) - c[0]) - 4 * static_cast<std::int64_t>(c[2]) -
                    2 * static_cast<std::int64_t>(c[3]),
                static_cast<std::uint64_t>(target.ticks) * target.ticks};
        }
        std::uint32_t into_ticks = target.ticks;
        Span<kAxes> ramp;
        if (approach_ticks > 0) {
            device::TickAcceleration start[kAxes];
            if (const Status s = device::plan_jerk_approach(t, g, target.ticks, acc, approach_ticks,
                                                            limits, ramp, start);
                s != Status::kOk) {
                return s;
            }
            for (unsigned a = 0; a < kAxes; ++a) {
                t[a] = ramp.control[a][0];
                g[a] = ramp.control[a][2];
                acc[a] = start[a];
            }
            into_ticks = ramp.ticks;
        }
        device::JerkMove<kAxes> move;
        if (const Status s = device::plan_jerk_reentry(f, t, g, into_ticks, acc, limits, move);
            s != Status::kOk) {
            return s;
        }
        out.clear();
        for (unsigned i = 0; i < move.count; ++i)
            out.push_back(from_core_span(move.span[i], target.subpath, false));
        if (approach_ticks > 0) out.push_back(from_core_span(ramp, target.subpath, true));
        return Status::kOk;
    });
}

// The core's timing and exact cubics of a Hermite span built here (the re-entry, the approach),
// as the planner's spans carry them, so a resumed job checks like a planned one.
void complete_core_span(CoreSpan& c) {
    if (make_span_timing(c.basis, c.ticks, c.timing) != Status::kOk) {
        throw std::range_error("a re-entry span's tick count is out of range");
    }
    c.cubic.assign(c.control.size(), TickCubic{});
    for (std::size_t a = 0; a < c.control.size(); ++a) {
        const std::int32_t control[4] = {c.control[a][0], c.control[a][1], c.control[a][2],
                                         c.control[a][3]};
        if (const Status s = make_tick_cubic(c.basis, control, c.timing, c.cubic[a]);
            s != Status::kOk) {
            throw std::range_error(std::string("the core refuses a re-entry span: ") +
                                   status_name(s));
        }
    }
}

}  // namespace

JobSpans resume_from(const JobSpans& job, std::size_t first, const std::vector<Lsb>& rest,
                     const DeviceLimitsLsb& limits, std::uint64_t spin_up_ticks) {
    while (first < job.origin.size() && job.origin[first] < 0) ++first;  // our own re-entry spans
    if (first >= job.plan.spans.size())
        throw std::invalid_argument("nothing left to draw: the job ran to its end");
    const CoreSpan& target = job.plan.spans[first];
    const std::size_t axes = target.control.size();
    if (rest.size() != axes)
        throw std::invalid_argument("the device's axis count differs from the job's");
    std::vector<std::int32_t> entry(axes), tangent(axes);
    for (std::size_t a = 0; a < axes; ++a) {
        entry[a] = target.control[a][0];
        tangent[a] = target.control[a][2];
    }
    JobSpans out;
    out.drawing_spans = job.drawing_spans;
    out.drawing_ticks = job.drawing_ticks;
    out.subpaths = job.subpaths;
    const auto add = [&](CoreSpan s, std::int64_t origin, std::uint64_t tick) {
        out.plan.spans.push_back(std::move(s));
        out.origin.push_back(origin);
        out.drawing_tick.push_back(tick);
    };
    // The lead-in spans (re-entry, approach), then the job's own from `first` on.
    const auto complete = [&](std::vector<CoreSpan> lead) {
        const std::uint64_t tick = job.drawing_tick[first];
        // The machine functions of the span re-entered are on from the start: a spindle that
        // runs there first spins up where the device rests (it was off while the device idled).
        for (CoreSpan& c : lead) c.machine = target.machine;
        for (std::uint64_t left = (target.machine & kOutputSpindle) != 0 ? spin_up_ticks : 0;
             left > 0;) {
            CoreSpan still;
            still.basis = Basis::kHermite;
            still.ticks = static_cast<std::uint32_t>(std::min<std::uint64_t>(left, kMaxSpanTicks));
            still.subpath = target.subpath;
            still.pen_down = false;
            still.machine = target.machine;
            for (std::size_t a = 0; a < axes; ++a)
                still.control.push_back({rest[a], rest[a], 0, 0});
            left -= still.ticks;
            complete_core_span(still);
            add(std::move(still), -1, tick);
        }
        for (CoreSpan& c : lead) {
            complete_core_span(c);
            add(std::move(c), -1, tick);
        }
        for (std::size_t i = first; i < job.plan.spans.size(); ++i) {
            if (job.origin[i] >= 0) add(job.plan.spans[i], job.origin[i], job.drawing_tick[i]);
        }
        std::uint64_t total = 0;
        for (const CoreSpan& c : out.plan.spans) total += c.ticks;
        out.plan.total_ticks = total;
        out.plan.pauses = pauses_from_spans(out.plan.spans);
        return out;
    };
    // Under a jerk limit the re-entry and the approach keep the acceleration continuous too
    // (jerk_reentry): the approach ends with the span's start acceleration, not none.
    const bool jerk = std::any_of(limits.max_jerk.begin(), limits.max_jerk.end(),
                                  [](std::uint32_t j) { return j != 0; });
    if (jerk) {
        const std::uint32_t approach_ticks = target.pen_down ? limits.pen_down_ticks : 0;
        std::vector<CoreSpan> lead;
        if (const Status s = jerk_reentry(rest, target, approach_ticks, limits, lead);
            s != Status::kOk) {
            throw std::range_error(
                std::string("no move from where the device rests back onto the drawing fits "
                            "the limits and the jerk limit (") +
                status_name(s) + ")");
        }
        return complete(std::move(lead));
    }
    // The pen lands where the span starts: approach along its start tangent, pen down, for
    // whole multiples of its length (k n ticks with tangent k T0: the same velocity, exactly).
    std::vector<CoreSpan> approach;
    if (target.pen_down && limits.pen_down_ticks > 0) {
        const std::uint32_t k = (limits.pen_down_ticks + target.ticks - 1) / target.ticks;
        CoreSpan a;
        a.basis = Basis::kHermite;
        a.ticks = k * target.ticks;
        a.subpath = target.subpath;
        a.pen_down = true;
        a.control.assign(axes, {});
        for (std::size_t i = 0; i < axes; ++i) {
            const std::int64_t t = static_cast<std::int64_t>(tangent[i]) * k;
            const std::int64_t start = static_cast<std::int64_t>(entry[i]) - t;
            if (t > kMaxTangentLsb || t < -kMaxTangentLsb || start > kMaxPositionLsb ||
                start < -kMaxPositionLsb) {
                throw std::range_error(
                    "the pen-down approach to the resume point leaves the position range");
            }
            a.control[i] = {static_cast<std::int32_t>(start), entry[i],
                            static_cast<std::int32_t>(t), static_cast<std::int32_t>(t)};
            entry[i] = static_cast<std::int32_t>(start);
        }
        approach.push_back(std::move(a));
    }
    CoreSpan r;
    r.subpath = target.subpath;
    r.pen_down = false;
    if (const Status s = reentry(rest, entry, tangent, target.ticks, limits, r); s != Status::kOk) {
        throw std::range_error(
            std::string("no move from where the device rests back onto the drawing fits "
                        "the limits in one span (") +
            status_name(s) + ")");
    }
    approach.insert(approach.begin(), std::move(r));
    return complete(std::move(approach));
}

}  // namespace pathstream::host
