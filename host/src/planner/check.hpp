// The per-tick check (check.cpp): every setpoint of a plan against the limits, the path and
// the pen dwells, fed in plan order so that a streamed plan is checked as it is made.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <utility>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pathstream/machine/core_span.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

class FeedTable;
class CoreStepper;
class PathProjector;
class PathWindow;

/// The per-tick check of check_plan, fed a plan in order (pen events before the spans at
/// their ticks), so that a streamed plan is checked as it is made.
class TickChecker {
public:
    /// `segments` (optional) give the feeds and, with `deviation`, the path to measure from.
    TickChecker(const MachineProfile& profile, const std::vector<BezierSegment>* segments,
                bool deviation);
    /// The same with the deviation measured against `path`, read as the check goes (the
    /// feeds too): memory O(a window of segments), not O(path). `path` must outlive it.
    TickChecker(const MachineProfile& profile, SegmentSource& path);
    ~TickChecker();
    TickChecker(const TickChecker&) = delete;
    TickChecker& operator=(const TickChecker&) = delete;
    /// A segment's requested feed (streamed plans give their segments' feeds as they are
    /// read): the first one of a subpath and pen state counts, as in the constructor.
    void note_feed(std::size_t subpath, bool pen_down, double feed);
    void pen(const PenEvent& event);
    /// Runs the span through the core tick by tick; throws PlanError if the core refuses it.
    void span(const CoreSpan& span);
    /// True when a tick or span so far is over a limit (exactly or after the allowance).
    bool over_limits();
    /// The held end point and the rest after it; the figures of the whole plan.
    PlanCheck finish();
    /// Called with every executed tick: its number, the core's setpoint (LSB per axis) and
    /// the pen output of the span playing it (the held end point last).
    using TickObserver =
        std::function<void(std::uint64_t tick, const std::int64_t* setpoint, bool pen_down)>;
    void observe(TickObserver observer) { observer_ = std::move(observer); }

private:
    bool pen_down_at(std::uint64_t tick);
    bool in_window(std::uint64_t tick);
    /// Tick k's setpoint p and exact value e, from a span with pen output `pen_output` and
    /// requested feed `feed`.
    void visit(const std::array<std::int64_t, kAxesMax>& p, const std::array<double, kAxesMax>& e,
               bool pen_output, double feed);
    void velocity(std::size_t a, double d, double de);
    void acceleration(std::size_t a, std::int64_t second, double de);
    /// The peaks below as fractions of the limits, into out_. A tick's figures are kept in LSB
    /// and divided once here: dividing by a positive limit keeps the order, so the largest
    /// quotient is the quotient of the largest, bit for bit.
    void fold_peaks();

    struct AxisPeaks {
        double velocity_allowed = 0, velocity_raw = 0, velocity_exact = 0;
        double acceleration_allowed = 0, acceleration_raw = 0, acceleration_exact = 0;
    };
    std::array<AxisPeaks, kAxesMax> peaks_{};

    const MachineProfile& profile_;
    std::size_t axes_;
    std::unique_ptr<FeedTable> feeds_;
    bool do_deviation_;
    PlanCheck out_;
    std::array<double, kAxesMax> vlim_{}, alim_{};
    std::unique_ptr<PathProjector> projector_;
    std::unique_ptr<PathWindow> window_;  ///< instead of projector_, for a path read as it goes
    std::unique_ptr<CoreStepper> stepper_;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> windows_;
    std::vector<PenEvent> pens_;
    std::size_t window_index_ = 0, pen_index_ = 0, spans_ = 0;
    bool pen_down_ = false;
    std::uint64_t tick_ = 0;
    std::array<std::int64_t, kAxesMax> p1_{}, p2_{};
    std::array<double, kAxesMax> e1_{}, e2_{};
    double prev_feed_ = 0;
    bool have_prev_span_ = false;
    double distance_ = 0;
    bool have_distance_ = false;
    std::array<double, kAxesMax> last_end_{};  ///< the last span's exact end point (LSB)
    bool last_pen_down_ = false;
    double last_feed_ = 0;
    TickObserver observer_;
};

/// check_plan, with the deviation part optional (the planner's own verification skips it).
PlanCheck check_plan_impl(const Plan& plan, const std::vector<BezierSegment>& segments,
                          const MachineProfile& profile, bool deviation);

}  // namespace pathstream::host::planner_detail
