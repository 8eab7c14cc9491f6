// The planner: Bezier geometry + machine profile -> timed Hermite spans of whole ticks for the
// core, and the per-tick check of a plan. Method and figures: docs/planner.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// Planning failed: the profile cannot be met or the input is unusable. what() says why and,
/// when it is about a place, where (subpath, mm along it).
class PlanError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Knobs of the planner. The defaults are what the CLI uses; bench_plan's optimum reference is
/// the same planner with a grid `reference_density` times denser.
struct PlanOptions {
    /// Grid of the lookahead (TOPP-RA backward pass): at most this arc length between nodes...
    double grid_step = 0.5;                 ///< mm
    std::size_t min_nodes_per_segment = 4;  ///< ...at least this many intervals per segment...
    double max_turn = 0.1;                  ///< ...and at most this tangent turn between nodes, rad

    /// Fractions of the machine's limits the executed spans are planned to. The per-tick check
    /// then verifies the whole plan against the full limits.
    double velocity_margin = 1.0;      ///< per-axis velocity (checked exactly on each span)
    double feed_margin = 0.999;        ///< requested feed (checked at eighths of each span)
    double acceleration_margin = 1.0;  ///< per-axis acceleration (checked exactly on each span)
    /// The lookahead (backward pass) plans speed changes with this fraction of the executed
    /// acceleration budget, and bends (curvature) with `lookahead_bend_margin` of it, so that
    /// spans of whole ticks can nearly always follow it (where not, see max_local_retries).
    double lookahead_margin = 0.98;
    double lookahead_bend_margin = 0.995;

    /// A joint turning by more than this (rad) is a corner where the motion stops exactly;
    /// smaller tangent jumps are crossed at the corner speed of docs/planner.md. A machine
    /// profile's corner_stop_angle, when it has one, replaces it.
    double corner_stop_angle = 0.35;
    /// Vertices between straight segments that turn by at most corner_stop_angle are replaced
    /// by a curve passing this fraction of the chord tolerance from the vertex (0: crossed as
    /// corners, with the corner speed of docs/planner.md §3). The planner follows the curve
    /// within half the tolerance, so the motion stays within the tolerance of the vertex.
    double corner_blend = 0.5;

    /// Segments read per window of plan_stream (plan_path too): memory grows with this, not
    /// with the job. A window is read further where its lookahead horizon needs it.
    std::size_t window_segments = 2048;
    /// ...and at most about this many ticks of motion at the segments' feeds (a window's spans
    /// are held until its check passes: this bounds a slow job's memory).
    std::uint64_t window_ticks = 250000;

    /// plan_stream checks each window tick by tick on a second thread while it plans the next
    /// (on a machine with more than one core): the same spans, sooner. False: one thread.
    bool check_on_thread = true;

    int max_replans = 8;         ///< whole-plan retries with lowered limits after a failed check
    int max_local_retries = 24;  ///< per piece: lookahead retries with a locally lowered margin
};

/// Figures of one planning run (for bench_plan and the CLI's verbose output).
struct PlanStats {
    std::size_t segments = 0;    ///< Bezier segments in
    std::size_t grid_nodes = 0;  ///< lookahead grid nodes
    std::size_t pieces = 0;      ///< stretches between stops (corners, pen changes, ends)
    /// Ticks of a regular span: the profile's ticks_per_span, or more where the limits are below
    /// what spans that short can meet exactly on the LSB grid (docs/planner.md).
    std::uint32_t ticks_per_span = 0;
    std::size_t motion_spans = 0;    ///< spans that move (dwells excluded)
    std::uint64_t motion_ticks = 0;  ///< ticks of motion (dwells excluded)
    std::uint64_t dwell_ticks = 0;   ///< ticks holding still while the pen moves
    int replans = 0;                 ///< whole-plan retries after a failed per-tick check
    std::size_t local_retries = 0;   ///< lookahead retries with a locally lowered margin
    double velocity_scale = 1;       ///< smallest factor applied to a velocity limit by replans
    double acceleration_scale = 1;   ///< same for acceleration limits
    /// Motion time (s) of the continuous TOPP-RA optimum on the same grid with the machine's
    /// full limits: the time-optimal reference the executed motion is compared with.
    double reference_motion_time = 0;
    /// With a jerk limit: ticks of the jerk stage's box filter (docs/planner.md §12), else 0.
    std::uint32_t jerk_filter_ticks = 0;
    /// With a jerk limit: motion ticks the jerk stage added to the second-order plan (the
    /// filter's length and the rest at the end of every piece), else 0.
    std::uint64_t jerk_added_ticks = 0;
    /// plan_stream: the most spans one window held before it went to the check (bounded by
    /// the window's length in segments and in ticks, not by the job).
    std::size_t max_window_spans = 0;
};

/// Plans `segments` (consecutive, continuous; to_bezier_segments makes them) for `profile`:
/// near time-optimal timing under per-axis velocity and acceleration limits, the requested
/// feeds, the chord tolerance and the corner rule; stops at sharp corners and pen changes,
/// with pen dwells. The result is Hermite spans of whole ticks (ticks_per_span each, shorter at
/// stops), every span validated by the core, continuous tick for tick, and verified on every
/// tick by check_plan (re-planned with lowered limits if needed).
/// `progress` (optional) receives a non-decreasing fraction in [0, 1].
/// Throws PlanError when the profile or the input is unusable or planning cannot converge.
Plan plan_path(const std::vector<BezierSegment>& segments, const MachineProfile& profile,
               const std::function<void(double fraction)>& progress = {});

/// The same with explicit options; `stats` (optional) receives the run's figures.
Plan plan_path(const std::vector<BezierSegment>& segments, const MachineProfile& profile,
               const PlanOptions& options, PlanStats* stats = nullptr,
               const std::function<void(double fraction)>& progress = {});

/// Receives a plan as it is made, in order: each pen event and pause before the spans that
/// follow it (a pause comes right after the span it ends, which carries pause_after).
/// Called from the planning thread only.
class PlanSink {
public:
    virtual ~PlanSink() = default;
    virtual void span(const CoreSpan& span) = 0;
    virtual void pen(const PenEvent& event) = 0;
    virtual void pause(const PlanPause& pause) = 0;
    /// The plan so far is void: planning starts over with lowered limits (a per-tick check
    /// failed, docs/planner.md §7). Return false when what was received cannot be taken back
    /// (then planning fails with PlanError).
    virtual bool restart() { return false; }
};

/// What a streamed plan came to (the Plan's totals, without its spans).
struct PlanTotals {
    std::size_t spans = 0;
    std::size_t pen_changes = 0;
    std::size_t pauses = 0;
    std::uint64_t total_ticks = 0;
    double duration = 0;       ///< s
    double path_length = 0;    ///< mm, pen-down
    double travel_length = 0;  ///< mm, pen-up
};

/// plan_path as a stream: plans the path in windows of segments with a bounded lookahead
/// (docs/planner.md §8), handing each window's spans to `sink` once they passed the per-tick
/// limit check, so that memory stays bounded whatever the job's length and the first spans
/// come out before the last segments are read. The result is the same kind of plan as
/// plan_path's (every span exact, checked on every tick); `stats`, when given, gets the
/// run's figures except reference_motion_time (0 here). Throws PlanError as plan_path, and
/// when a replan is needed but `sink` or `source` cannot start over.
PlanTotals plan_stream(SegmentSource& source, const MachineProfile& profile,
                       const PlanOptions& options, PlanSink& sink, PlanStats* stats = nullptr,
                       const std::function<void(double fraction)>& progress = {});

/// What plan_stream's own per-tick check measures beyond the limits, for a caller that wants
/// the whole PlanCheck without checking the plan a second time.
struct StreamCheck {
    /// The path to measure the deviation from: a pass of its own over the planned path (not
    /// the planner's source), read as the check goes (PlanChecker(SegmentSource&) explains
    /// the window). Null: no deviation (0 in the result).
    SegmentSource* path = nullptr;
    /// When planning succeeded: the figures of the whole plan, jerk included (check_plan's).
    PlanCheck result;
};

/// plan_stream with its check's figures in `check` (optional).
PlanTotals plan_stream(SegmentSource& source, const MachineProfile& profile,
                       const PlanOptions& options, PlanSink& sink, StreamCheck* check,
                       PlanStats* stats = nullptr,
                       const std::function<void(double fraction)>& progress = {});

namespace planner_detail {
class TickChecker;
class JerkMeter;
}  // namespace planner_detail

/// check_plan for a plan handed over in order, as a PlanSink (plan_stream's, or a chain):
/// the same figures from finish(), without the plan held in memory. `segments` and `profile`
/// must outlive it. Throws PlanError as check_plan when the core refuses a span.
class PlanChecker : public PlanSink {
public:
    PlanChecker(const std::vector<BezierSegment>& segments, const MachineProfile& profile);
    /// The same with the path read from `path` as the check goes (its own source: not the one
    /// being planned), so that memory stays flat: the deviation is then measured against the
    /// path near the motion (docs/planner.md §7), never below check_plan's.
    PlanChecker(SegmentSource& path, const MachineProfile& profile);
    ~PlanChecker() override;
    void span(const CoreSpan& span) override;
    void pen(const PenEvent& event) override;
    void pause(const PlanPause&) override { ++pauses_; }
    /// Called with every executed tick as the core makes it: tick number, setpoint (LSB per
    /// axis) and the pen output (the held end point comes last, from finish()).
    void on_tick(
        std::function<void(std::uint64_t tick, const std::int64_t* setpoint, bool pen_down)>
            observer);
    /// The held end point; the figures of the whole plan.
    PlanCheck finish();
    std::size_t spans() const { return spans_; }
    std::size_t pen_changes() const { return pens_; }
    std::size_t pauses() const { return pauses_; }
    std::uint64_t ticks() const { return ticks_; }

private:
    std::unique_ptr<planner_detail::TickChecker> impl_;
    std::unique_ptr<planner_detail::JerkMeter> jerk_;
    std::size_t spans_ = 0, pens_ = 0, pauses_ = 0;
    std::uint64_t ticks_ = 0;
};

/// Checks every executed tick of `plan`: the integer setpoints as the core produces them
/// (SetpointStream: continuity of every span is enforced) against the per-axis limits, with
/// the rounding allowance of docs/planner.md; the distance of every pen-down setpoint from the
/// geometric path; and that no axis moves while the pen settles. Throws PlanError if the plan
/// is malformed (a span the core refuses, a discontinuity, axes that do not match).
PlanCheck check_plan(const Plan& plan, const std::vector<BezierSegment>& segments,
                     const MachineProfile& profile);

}  // namespace pathstream::host
