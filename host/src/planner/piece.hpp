// One piece planned on its window's lookahead, with the local retries that lower the lookahead
// where the forward pass got stuck (piece.cpp).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "limits.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// The lookahead of one window's grid: speed caps, acceleration factors and the backward
/// pass's beta per node, lowered locally by the retries of plan_piece.
struct WindowLookahead {
    WindowLookahead(const PathGrid& pg, const Limits& limits, const MachineProfile& profile,
                    const PlanOptions& options);
    void set_factor(std::size_t k);

    const PathGrid& pg;
    const Limits& limits;
    const MachineProfile& profile;
    const PlanOptions& options;
    double end_zone;  ///< half an LSB: dips this close to a piece's end count as it (backward_pass)
    std::vector<double> base_caps, caps, local_factor, local_cap, corner_factor, factor, beta, dip;
};

/// Plans one piece: backward pass, forward pass from rest at start_q (or from the last knot
/// of `carried`, whose spans were sent already and are kept first in the result), and the
/// local retries. Throws PlanError naming the place when no whole-tick motion is found.
/// `run_offset`: mm of the run before this window's grid, for that message.
PieceMotion plan_piece(WindowLookahead& lookahead, const Piece& piece, const Vec& start_q,
                       PieceMotion* carried, double run_offset, PlanStats& stats);

/// "subpath N, X mm along it" for a place in a piece.
std::string where(const PathGrid& pg, const Piece& piece, double lambda, double run_offset);

}  // namespace pathstream::host::planner_detail
