// Knots, runs and pen changes into the plan's core spans, pen events, dwells and pauses
// (emit.cpp), each span validated by the core as the device will.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/machine/core_span.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// One event of a plan in the making, in plan order.
struct PlanEvent {
    enum class Kind { kSpan, kPen, kPause };
    Kind kind = Kind::kSpan;
    CoreSpan span;
    PenEvent pen;
    PlanPause pause;
};

/// Turns knots, runs and pen changes into the plan's core spans, pen events, dwells and
/// pauses, in order (docs/planner.md §6). The last span is held back until the next event,
/// because a pause marks the span it follows; finish() lets it go. Throws PlanError when a
/// value is outside the core's range or the core refuses a span.
class SpanEmitter {
public:
    SpanEmitter(const MachineProfile& profile, std::size_t axes, const Vec& start_mm);
    /// The start of a run: its pause, pen change and rests, unless it continues the current
    /// run (the same pen state and subpath: a run cut between two windows).
    void begin_run(const Run& run);
    /// A piece starts at `start_mm`: it must be where the last one ended (within 1 LSB).
    void piece_start(const Vec& start_mm, std::size_t subpath);
    /// The motion span from knot `from` to `span.end`.
    void motion(const Knot& from, const MotionSpan& span, const Run& run);
    using LsbVec = std::array<std::int64_t, kAxesMax>;
    /// A motion span given in LSB: from the current position to `p1` with tangents t0, t1.
    void motion_lsb(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks,
                    std::size_t subpath, bool pen_down);
    /// Where the last span ended (LSB).
    const LsbVec& position() const { return pos_; }
    /// The last span's end acceleration per axis: numerator (LSB/u^2) over `last_ticks()`^2
    /// (0 at rest: before the first span, after a dwell).
    const LsbVec& last_end_acceleration() const { return a_end_; }
    std::uint32_t last_ticks() const { return last_ticks_; }
    /// With jerk limits (LSB/tick^3 per axis; infinity: none) every span is verified against
    /// them exactly: its own jerk and the acceleration step at its join with the last span.
    void set_jerk_limits(const std::array<double, kAxesMax>& jerk_lsb) {
        jerk_lsb_ = jerk_lsb;
        check_jerk_ = true;
    }
    /// The end of the job: the final lift and its dwell, and the held-back span.
    void finish(std::size_t last_subpath);
    /// The events made since the last call, moved into `out` (emptied first through recycle).
    void take(std::vector<PlanEvent>& out);
    /// Empties `used` (events already handed on), keeping its spans' storage for the next
    /// spans: a caller that gives every event back allocates nothing per span once warm.
    void recycle(std::vector<PlanEvent>& used);

    std::uint64_t total_ticks() const { return total_ticks_; }
    std::size_t motion_spans() const { return motion_spans_; }
    std::uint64_t motion_ticks() const { return motion_ticks_; }
    std::uint64_t dwell_ticks() const { return dwell_ticks_; }
    /// Of the dwell ticks, those waiting for the spindle to spin up; and how often it did.
    std::uint64_t spin_up_ticks() const { return spin_up_ticks_; }
    std::size_t spin_ups() const { return spin_ups_; }

private:
    LsbVec quantise(const Vec& mm) const;
    LsbVec tangent(const Vec& velocity, std::uint32_t ticks) const;
    void span(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks,
              std::size_t subpath, bool pen_down);
    void dwell(std::uint64_t ticks, std::size_t subpath, bool pen_down);
    void pen(bool down, std::size_t subpath, bool last);
    void before_pen_down(const Run& run);
    void set_machine(std::uint8_t machine, std::size_t subpath);
    void release();
    void verify_jerk(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks,
                     std::size_t subpath);
    [[noreturn]] static void fail(std::size_t subpath, const std::string& what);

    LsbVec a_end_{};
    std::uint32_t last_ticks_ = 1;
    std::array<double, kAxesMax> jerk_lsb_{};
    bool check_jerk_ = false;

    const MachineProfile& profile_;
    std::size_t axes_;
    std::vector<PlanEvent> events_;
    std::vector<CoreSpan> spare_;  ///< spans taken back by take(), their vectors' storage reused
    bool held_ = false;            ///< events_.back() is a span held back
    bool any_span_ = false, last_pen_down_ = false;
    LsbVec pos_{};
    bool pen_ = false;
    std::uint8_t machine_ = 0;  ///< the machine functions the spans carry now
    bool in_run_ = false;
    std::size_t run_subpath_ = 0;
    bool run_pen_down_ = false;
    std::uint64_t total_ticks_ = 0;
    std::size_t motion_spans_ = 0;
    std::uint64_t motion_ticks_ = 0, dwell_ticks_ = 0, spin_up_ticks_ = 0;
    std::size_t spin_ups_ = 0;
    std::uint32_t shaper_rest_ticks_ = 0;  ///< plan_for_shaper: the rest before moving again
    /// Still ticks since the last span that moved (the start counts as a long rest).
    std::uint64_t rested_ticks_ = std::numeric_limits<std::uint32_t>::max();
};

}  // namespace pathstream::host::planner_detail
