// Knots and pen dwells -> the plan's Hermite core spans, each validated by the core.
//
// A motion span from knot j to knot j+1 lasting m ticks is the Hermite span (P0, P1, T0, T1)
// with P = the knot's point rounded to LSB and T = velocity * (m / tick_hz) rounded to LSB
// (dp/du over the span). Consecutive spans share P exactly, and T whenever they have the same
// tick count, so the core's cubic is continuous tick for tick.
#include "emit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "lsb_rounding.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/core_span.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "pathstream/units.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

SpanEmitter::SpanEmitter(const MachineProfile& profile, std::size_t axes, const Vec& start_mm)
    : profile_(profile), axes_(axes) {
    pos_ = quantise(start_mm);
    if (profile.plan_for_shaper) shaper_rest_ticks_ = profile_shaper_spread(profile).longest_delay;
}

SpanEmitter::LsbVec SpanEmitter::quantise(const Vec& mm) const {
    LsbVec r{};
    for (std::size_t i = 0; i < axes_; ++i) r[i] = std::llround(mm[i] / profile_.mm_per_lsb);
    return r;
}

SpanEmitter::LsbVec SpanEmitter::tangent(const Vec& velocity, std::uint32_t ticks) const {
    const double scale = tangent_scale(ticks, profile_.tick_hz, profile_.mm_per_lsb);
    LsbVec r{};
    for (std::size_t i = 0; i < axes_; ++i) r[i] = scaled_tangent_lsb(velocity[i], scale);
    return r;
}

void SpanEmitter::release() {
    held_ = false;
}

void SpanEmitter::span(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks,
                       std::size_t subpath, bool pen_down) {
    // With plan_for_shaper, motion that stopped rests the shapers' longest delay before it moves
    // again: no window of the shaped command then holds points of both legs of a corner, so it
    // turns the corner exactly instead of cutting it.
    const bool moves = p1 != pos_ || t0 != LsbVec{} || t1 != LsbVec{};
    if (moves && t0 == LsbVec{} && rested_ticks_ < shaper_rest_ticks_)
        dwell(shaper_rest_ticks_ - rested_ticks_, subpath, last_pen_down_);
    // Still ticks at the end of the plan so far: 0 after a span that moves (one that ends at
    // rest starts the count).
    rested_ticks_ = moves ? 0 : rested_ticks_ + ticks;
    PlanEvent ev;
    CoreSpan& s = ev.span;
    if (!spare_.empty()) {  // a span taken back: its vectors' storage, emptied
        s.control = std::move(spare_.back().control);
        s.cubic = std::move(spare_.back().cubic);
        spare_.pop_back();
        s.control.clear();
        s.cubic.clear();
    }
    s.basis = Basis::kHermite;
    s.ticks = ticks;
    s.subpath = subpath;
    s.pen_down = pen_down;
    s.machine = machine_;
    if (make_span_timing(s.basis, ticks, s.timing) != Status::kOk)
        fail(subpath, "span ticks out of range");
    if (check_jerk_) verify_jerk(p1, t0, t1, ticks, subpath);
    const LsbVec* values[4] = {&pos_, &p1, &t0, &t1};
    s.control.reserve(axes_);
    s.cubic.reserve(axes_);
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
        if (const Status st = make_tick_cubic(s.basis, control, s.timing, cubic);
            st != Status::kOk) {
            fail(subpath, std::string("axis ") + std::to_string(a) +
                              ": the core rejects a span: " + status_name(st));
        }
        s.control.push_back(c);
        s.cubic.push_back(cubic);
    }
    for (std::size_t a = 0; a < axes_; ++a)
        a_end_[a] = -6 * (p1[a] - pos_[a]) + 2 * t0[a] + 4 * t1[a];
    last_ticks_ = ticks;
    release();
    events_.push_back(std::move(ev));
    held_ = true;
    any_span_ = true;
    last_pen_down_ = pen_down;
    total_ticks_ += ticks;
    pos_ = p1;
}

void SpanEmitter::dwell(std::uint64_t ticks, std::size_t subpath, bool pen_down) {
    while (ticks > 0) {
        const std::uint32_t m =
            static_cast<std::uint32_t>(std::min<std::uint64_t>(ticks, kMaxSpanTicks));
        span(pos_, LsbVec{}, LsbVec{}, m, subpath, pen_down);
        ticks -= m;
        dwell_ticks_ += m;
    }
}

void SpanEmitter::pen(bool down, std::size_t subpath, bool last) {
    // Planned for the shaper, the pen changes once the shaped axes have arrived too: a stroke's
    // end is drawn before the pen lifts, and the pen lands where the shaped travel ends.
    if (rested_ticks_ < shaper_rest_ticks_ && any_span_)
        dwell(shaper_rest_ticks_ - rested_ticks_, subpath, pen_);
    release();
    PlanEvent ev;
    ev.kind = PlanEvent::Kind::kPen;
    ev.pen = {total_ticks_, down};
    events_.push_back(std::move(ev));
    std::uint64_t d =
        delay_ticks(down ? profile_.pen_down_delay : profile_.pen_up_delay, profile_.tick_hz);
    if (last && d == 0) d = 1;  // the final lift needs a span that carries it
    dwell(d, subpath, down);
    pen_ = down;
}

// At rest: the machine functions change with a still span that carries them (the device
// switches outputs at a span's first tick), lasting the spindle's spin-up when it starts or
// reverses, so that no motion happens before it runs at speed.
void SpanEmitter::set_machine(std::uint8_t machine, std::size_t subpath) {
    if (machine == machine_) return;
    const bool on = (machine & kOutputSpindle) != 0;
    const bool starts = on && ((machine_ & kOutputSpindle) == 0 ||
                               ((machine ^ machine_) & kOutputSpindleReverse) != 0);
    machine_ = machine;
    std::uint64_t ticks = 1;
    if (starts) {
        const std::uint64_t spin_up = delay_ticks(profile_.spindle.spin_up, profile_.tick_hz);
        if (spin_up > 0) {
            ticks = spin_up;
            spin_up_ticks_ += spin_up;
        }
        ++spin_ups_;
    }
    dwell(ticks, subpath, pen_);
}

// Before a subpath's pen goes down (or a routed travel starts): its programmed pause (the
// device holds at the end of the last span, which must be a still pen-up one, carrying the
// machine functions the pause holds with), its machine functions and its pen-up rest.
void SpanEmitter::before_pen_down(const Run& run) {
    if (run.pause_before) {
        set_machine(run.pause_outputs, run.subpath);
        // The pause follows a still pen-up span, held back so that it can be marked.
        if (!any_span_ || last_pen_down_ || !held_) dwell(1, run.subpath, false);
        events_.back().span.pause_after = true;
        release();
        PlanEvent ev;
        ev.kind = PlanEvent::Kind::kPause;
        ev.pause = {total_ticks_, run.subpath};
        events_.push_back(std::move(ev));
    }
    set_machine(run.outputs, run.subpath);
    if (run.dwell_before > 0 && !run.dwell_pen_down) {
        dwell(delay_ticks(run.dwell_before, profile_.tick_hz), run.subpath, false);
    }
}

void SpanEmitter::begin_run(const Run& run) {
    if (in_run_ && run.pen_down == run_pen_down_ && run.subpath == run_subpath_)
        return;  // continued
    in_run_ = true;
    run_pen_down_ = run.pen_down;
    run_subpath_ = run.subpath;
    if (!run.pen_down) {
        // A travel subpath the file routes (G-code rapids): a dwell with the pen down happens
        // before the lift; its pause and a pen-up dwell after it, where the machine rests.
        const bool dwell_down = run.dwell_before > 0 && run.dwell_pen_down && pen_;
        if (dwell_down) dwell(delay_ticks(run.dwell_before, profile_.tick_hz), run.subpath, true);
        if (pen_) pen(false, run.subpath, false);
        before_pen_down(run);  // the pause, and the dwell when it was asked with the pen up
        if (run.dwell_before > 0 && run.dwell_pen_down && !dwell_down)
            dwell(delay_ticks(run.dwell_before, profile_.tick_hz), run.subpath, false);
        return;
    }
    if (!pen_) before_pen_down(run);
    set_machine(run.outputs, run.subpath);  // pen down already: it changes here, at rest
    if (!pen_) pen(true, run.subpath, false);
    if (run.pen_down && run.dwell_before > 0 && run.dwell_pen_down) {
        dwell(delay_ticks(run.dwell_before, profile_.tick_hz), run.subpath, true);
    }
}

void SpanEmitter::piece_start(const Vec& start_mm, std::size_t subpath) {
    const LsbVec start = quantise(start_mm);
    for (std::size_t a = 0; a < axes_; ++a) {
        if (std::llabs(start[a] - pos_[a]) > 1)
            fail(subpath, "internal: a piece does not start where the last one ended");
    }
}

void SpanEmitter::motion(const Knot& from, const MotionSpan& s, const Run& run) {
    span(quantise(s.end.q), tangent(from.v, s.ticks), tangent(s.end.v, s.ticks), s.ticks,
         run.subpath, run.pen_down);
    ++motion_spans_;
    motion_ticks_ += s.ticks;
}

void SpanEmitter::motion_lsb(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1,
                             std::uint32_t ticks, std::size_t subpath, bool pen_down) {
    span(p1, t0, t1, ticks, subpath, pen_down);
    ++motion_spans_;
    motion_ticks_ += ticks;
}

// The jerk rules of docs/planner.md §12 on the exact integer span, before it is made: its
// third derivative 6 (2 P0 - 2 P1 + T0 + T1) / n^3 and the step from the last span's end
// acceleration to its start acceleration (6 (P1 - P0) - 4 T0 - 2 T1) / n^2, both within J.
void SpanEmitter::verify_jerk(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1,
                              std::uint32_t ticks, std::size_t subpath) {
    const long double n = ticks, m = last_ticks_;
    for (std::size_t a = 0; a < axes_; ++a) {
        const long double j = jerk_lsb_[a];
        if (!std::isfinite(static_cast<double>(j))) continue;
        const std::int64_t dp = p1[a] - pos_[a];
        const long double third =
            std::fabs(static_cast<long double>(6 * (-2 * dp + t0[a] + t1[a])));
        const long double start = static_cast<long double>(6 * dp - 4 * t0[a] - 2 * t1[a]);
        const long double step =
            std::fabs(start * m * m - static_cast<long double>(a_end_[a]) * n * n);
        if (third > j * n * n * n || step > j * n * n * m * m) {
            std::ostringstream msg;
            msg << "axis " << a << ": a span at tick " << total_ticks_
                << " exceeds the jerk limit of " << j << " LSB/tick^3 ("
                << (third > j * n * n * n ? "inside the span" : "at its join with the last one")
                << ")";
            fail(subpath, msg.str());
        }
    }
}

void SpanEmitter::finish(std::size_t last_subpath) {
    if (pen_) pen(false, last_subpath, true);
    if (check_jerk_) {  // the job ends at rest
        const long double n = last_ticks_;
        for (std::size_t a = 0; a < axes_; ++a) {
            if (std::fabs(static_cast<long double>(a_end_[a])) > jerk_lsb_[a] * n * n) {
                fail(last_subpath, "axis " + std::to_string(a) +
                                       ": the last span does not end within the jerk limit");
            }
        }
    }
    release();
}

void SpanEmitter::take(std::vector<PlanEvent>& out) {
    // The two buffers trade places, so both keep their capacity from window to window.
    recycle(out);
    if (held_) {  // keep the held-back span for the next call
        PlanEvent last = std::move(events_.back());
        events_.pop_back();
        out.swap(events_);
        events_.push_back(std::move(last));
    } else {
        out.swap(events_);
    }
}

void SpanEmitter::recycle(std::vector<PlanEvent>& used) {
    for (PlanEvent& e : used) {
        if (e.kind == PlanEvent::Kind::kSpan) spare_.push_back(std::move(e.span));
    }
    used.clear();
}

void SpanEmitter::fail(std::size_t subpath, const std::string& what) {
    throw PlanError("subpath " + std::to_string(subpath) + ": " + what);
}

}  // namespace pathstream::host::planner_detail
