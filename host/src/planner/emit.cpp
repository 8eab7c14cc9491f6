// Knots and pen dwells -> the plan's Hermite core spans, each validated by the core.
//
// A motion span from knot j to knot j+1 lasting m ticks is the Hermite span (P0, P1, T0, T1)
// with P = the knot's point rounded to LSB and T = velocity * (m / tick_hz) rounded to LSB
// (dp/du over the span). Consecutive spans share P exactly, and T whenever they have the same
// tick count, so the core's cubic is continuous tick for tick.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "internal.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host::planner_detail {
namespace {

using LsbVec = std::array<std::int64_t, kAxesMax>;

class Emitter {
public:
    Emitter(const PathGrid& g, const MachineProfile& profile) : g_(g), profile_(profile), axes_(g.grid.axes) {}

    LsbVec quantise(const Vec& mm) const {
        LsbVec r{};
        for (std::size_t i = 0; i < axes_; ++i) r[i] = std::llround(mm[i] / profile_.mm_per_lsb);
        return r;
    }
    LsbVec tangent(const Vec& velocity, std::uint32_t ticks) const {
        const double scale = ticks / profile_.tick_hz / profile_.mm_per_lsb;
        LsbVec r{};
        for (std::size_t i = 0; i < axes_; ++i) r[i] = std::llround(velocity[i] * scale);
        return r;
    }

    void span(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks, std::size_t subpath,
              bool pen_down) {
        CoreSpan s;
        s.basis = Basis::kHermite;
        s.ticks = ticks;
        s.subpath = subpath;
        s.pen_down = pen_down;
        if (make_span_timing(s.basis, ticks, s.timing) != Status::kOk) fail(subpath, "span ticks out of range");
        const LsbVec* values[4] = {&pos_, &p1, &t0, &t1};
        for (std::size_t a = 0; a < axes_; ++a) {
            std::array<std::int32_t, 4> c{};
            for (std::size_t k = 0; k < 4; ++k) {
                const std::int64_t v = (*values[k])[a];
                const std::int64_t limit = k >= 2 ? kMaxTangentLsb : kMaxPositionLsb;
                if (v < -limit || v > limit) {
                    std::ostringstream m;
                    m << "axis " << a << (k >= 2 ? " velocity term " : " position ") << v
                      << " LSB is outside the core's range +/-" << limit
                      << " LSB (use a coarser mm_per_lsb or move the drawing)";
                    fail(subpath, m.str());
                }
                c[k] = static_cast<std::int32_t>(v);
            }
            const std::int32_t control[4] = {c[0], c[1], c[2], c[3]};
            TickCubic cubic;
            if (const Status st = make_tick_cubic(s.basis, control, s.timing, cubic); st != Status::kOk) {
                fail(subpath, std::string("axis ") + std::to_string(a) + ": the core rejects a span: " + status_name(st));
            }
            s.control.push_back(c);
            s.cubic.push_back(cubic);
        }
        plan_.spans.push_back(std::move(s));
        plan_.total_ticks += ticks;
        pos_ = p1;
    }

    void dwell(std::uint64_t ticks, std::size_t subpath, bool pen_down) {
        while (ticks > 0) {
            const std::uint32_t m = static_cast<std::uint32_t>(std::min<std::uint64_t>(ticks, kMaxSpanTicks));
            span(pos_, LsbVec{}, LsbVec{}, m, subpath, pen_down);
            ticks -= m;
            dwell_ticks_ += m;
        }
    }

    void pen(bool down, std::size_t subpath, bool last) {
        plan_.pen.push_back({plan_.total_ticks, down});
        std::uint64_t d = delay_ticks(down ? profile_.pen_down_delay : profile_.pen_up_delay, profile_.tick_hz);
        if (last && d == 0) d = 1;  // the final lift needs a span that carries it
        dwell(d, subpath, down);
        pen_ = down;
    }

    // Before a subpath's pen goes down: its programmed pause (the device holds at the end of
    // the last span, which must be a still pen-up one) and its pen-up rest.
    void before_pen_down(const Run& run) {
        if (run.pause_before) {
            if (plan_.spans.empty() || plan_.spans.back().pen_down) dwell(1, run.subpath, false);
            plan_.spans.back().pause_after = true;
            plan_.pauses.push_back({plan_.total_ticks, run.subpath});
        }
        if (run.dwell_before > 0 && !run.dwell_pen_down) {
            dwell(delay_ticks(run.dwell_before, profile_.tick_hz), run.subpath, false);
        }
    }

    Plan run(const std::vector<PieceMotion>& motion, PlanStats* stats) {
        if (g_.runs.empty()) return plan_;
        pos_ = quantise(g_.runs.front().start);
        for (const Run& run : g_.runs) {
            if (run.pen_down && !pen_) before_pen_down(run);
            if (run.pen_down != pen_) pen(run.pen_down, run.subpath, false);
            if (run.pen_down && run.dwell_before > 0 && run.dwell_pen_down) {
                dwell(delay_ticks(run.dwell_before, profile_.tick_hz), run.subpath, true);
            }
            for (std::size_t p : run.pieces) {
                const PieceMotion& m = motion[p];
                const LsbVec start = quantise(m.start.q);
                for (std::size_t a = 0; a < axes_; ++a) {
                    if (std::llabs(start[a] - pos_[a]) > 1) fail(run.subpath, "internal: a piece does not start where the last one ended");
                }
                const Knot* prev = &m.start;
                for (const MotionSpan& s : m.spans) {
                    span(quantise(s.end.q), tangent(prev->v, s.ticks), tangent(s.end.v, s.ticks), s.ticks, run.subpath,
                         run.pen_down);
                    prev = &s.end;
                    ++motion_spans_;
                    motion_ticks_ += s.ticks;
                }
            }
        }
        if (pen_) pen(false, g_.runs.back().subpath, true);
        plan_.duration = static_cast<double>(plan_.total_ticks) / profile_.tick_hz;
        plan_.path_length = g_.pen_down_length;
        plan_.travel_length = g_.travel_length;
        if (stats != nullptr) {
            stats->motion_spans = motion_spans_;
            stats->motion_ticks = motion_ticks_;
            stats->dwell_ticks = dwell_ticks_;
        }
        return std::move(plan_);
    }

private:
    [[noreturn]] static void fail(std::size_t subpath, const std::string& what) {
        throw PlanError("subpath " + std::to_string(subpath) + ": " + what);
    }

    const PathGrid& g_;
    const MachineProfile& profile_;
    std::size_t axes_;
    Plan plan_;
    LsbVec pos_{};
    bool pen_ = false;
    std::size_t motion_spans_ = 0;
    std::uint64_t motion_ticks_ = 0, dwell_ticks_ = 0;
};

}  // namespace

Plan emit_plan(const PathGrid& g, const std::vector<PieceMotion>& motion, const MachineProfile& profile,
               PlanStats* stats) {
    return Emitter(g, profile).run(motion, stats);
}

}  // namespace pathstream::host::planner_detail
