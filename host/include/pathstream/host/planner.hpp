// The planner: Bezier geometry + machine profile -> timed Hermite spans of whole ticks for the
// core, and the per-tick check of a plan. Method and figures: docs/planner.md.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/machine.hpp"
#include "pathstream/host/plan.hpp"

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
    double velocity_margin = 1.0;        ///< per-axis velocity (checked exactly on each span)
    double feed_margin = 0.999;          ///< requested feed (checked at eighths of each span)
    double acceleration_margin = 1.0;    ///< per-axis acceleration (checked exactly on each span)
    /// The lookahead (backward pass) plans speed changes with this fraction of the executed
    /// acceleration budget, and bends (curvature) with `lookahead_bend_margin` of it, so that
    /// spans of whole ticks can nearly always follow it (where not, see max_local_retries).
    double lookahead_margin = 0.98;
    double lookahead_bend_margin = 0.995;

    /// A joint turning by more than this (rad) is a corner where the motion stops exactly;
    /// smaller tangent jumps are crossed at the corner speed of docs/planner.md.
    double corner_stop_angle = 0.35;

    int max_replans = 8;          ///< whole-plan retries with lowered limits after a failed check
    int max_local_retries = 24;   ///< per piece: lookahead retries with a locally lowered margin
};

/// Figures of one planning run (for bench_plan and the CLI's verbose output).
struct PlanStats {
    std::size_t segments = 0;          ///< Bezier segments in
    std::size_t grid_nodes = 0;        ///< lookahead grid nodes
    std::size_t pieces = 0;            ///< stretches between stops (corners, pen changes, ends)
    /// Ticks of a regular span: the profile's ticks_per_span, or more where the limits are below
    /// what spans that short can meet exactly on the LSB grid (docs/planner.md).
    std::uint32_t ticks_per_span = 0;
    std::size_t motion_spans = 0;      ///< spans that move (dwells excluded)
    std::uint64_t motion_ticks = 0;    ///< ticks of motion (dwells excluded)
    std::uint64_t dwell_ticks = 0;     ///< ticks holding still while the pen moves
    int replans = 0;                   ///< whole-plan retries after a failed per-tick check
    std::size_t local_retries = 0;     ///< lookahead retries with a locally lowered margin
    double velocity_scale = 1;         ///< smallest factor applied to a velocity limit by replans
    double acceleration_scale = 1;     ///< same for acceleration limits
    /// Motion time (s) of the continuous TOPP-RA optimum on the same grid with the machine's
    /// full limits: the time-optimal reference the executed motion is compared with.
    double reference_motion_time = 0;
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

/// Checks every executed tick of `plan`: the integer setpoints as the core produces them
/// (SetpointStream: continuity of every span is enforced) against the per-axis limits, with
/// the rounding allowance of docs/planner.md; the distance of every pen-down setpoint from the
/// geometric path; and that no axis moves while the pen settles. Throws PlanError if the plan
/// is malformed (a span the core refuses, a discontinuity, axes that do not match).
PlanCheck check_plan(const Plan& plan, const std::vector<BezierSegment>& segments,
                     const MachineProfile& profile);

}  // namespace pathstream::host
