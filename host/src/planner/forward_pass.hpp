// The executed motion of a piece in whole ticks, its knots and spans, and forward_pass, which
// makes it (PieceTimer, piece_timer.hpp).
#pragma once

#include <cstdint>
#include <vector>

#include "grid.hpp"
#include "limits.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// A knot of the executed motion: arc length, speed, point and velocity vector (mm, mm/s).
struct Knot {
    double lambda = 0, speed = 0;
    Vec q{}, v{};
};
/// A span of the executed motion: `ticks` ticks ending at `end` (it starts at the previous end).
struct MotionSpan {
    std::uint32_t ticks = 0;
    Knot end;
};
struct PieceMotion {
    Knot start;
    std::vector<MotionSpan> spans;
    bool ok = true;
    double fail_lambda = 0;  ///< where the forward pass got stuck (when !ok)
    double fail_speed = 0;   ///< and how fast it was going there
};

/// The executed motion of one piece in whole ticks: knots every ticks_per_span ticks with
/// constant acceleration along the path in each span, the Hermite span between two knots
/// checked against the limits, the speed kept under beta, and the final span ending at rest
/// exactly at the piece's end.
/// Knots are on the LSB grid and their velocities rounded as the emitter rounds tangents, so
/// that what is checked is exactly what the device runs; `start_q` is where the previous piece
/// ended (on the grid).
/// `resume` (optional): a previous attempt whose knots before `resume_lambda` are kept (its
/// spans are moved into the result and cut there).
/// `short_spans`: allow spans shorter than ticks_per_span where a full one cannot be found
/// (the last resort: their tangents are rounded on a different scale).
PieceMotion forward_pass(const PathGrid& g, const Piece& piece, const Limits& limits,
                         const std::vector<double>& caps, const std::vector<double>& beta,
                         const MachineProfile& profile, const PlanOptions& options,
                         const Vec& start_q, PieceMotion* resume = nullptr,
                         double resume_lambda = 0, bool short_spans = false);

}  // namespace pathstream::host::planner_detail
