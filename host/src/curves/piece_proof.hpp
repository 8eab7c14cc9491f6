// The proof that one cubic Bezier piece stays within a tolerance of the curve it was fitted to,
// over the piece's whole parameter interval (not only at samples).
#pragma once

#include <array>
#include <cstddef>
#include <vector>

#include "expression.hpp"

namespace pathstream::host::curves {

/// One cubic piece over the parameter interval [a, b]: per coordinate the four Bezier values,
/// reached at u = (t - a) / (b - a).
struct BezierPiece {
    double a = 0;
    double b = 1;
    std::vector<std::array<double, 4>> control;  ///< one per coordinate
};

/// How a proof ended.
struct PieceProof {
    bool proven = false;    ///< every cell's bound is at most the tolerance
    double bound = 0;       ///< proven: the largest cell bound (mm), an upper bound of the error
    std::size_t cells = 0;  ///< cells evaluated
    /// Not proven: a t in the cell that failed last, and whether its enclosure was unbounded or
    /// undefined there (rather than only too wide).
    double failed_at = 0;
    bool unbounded = false;
};

/// Proves max over t in [a, b] of |curve(t) - piece(t)| (Euclidean over the coordinates) is at
/// most `tolerance`, by splitting [a, b] into cells and bounding each cell J with midpoint m by
/// |e(m)| + |e'(J)| · radius(J) per coordinate, where e = curve - piece, e(m) is enclosed by
/// interval evaluation at the point m and e'(J) = curve'(J) - piece'(J) by interval
/// differentiation and the Bezier hull of the piece's quadratic derivative. Cells whose bound
/// is too large are halved until `max_cells` have been evaluated. Cost: O(cells × nodes);
/// never throws (a curve undefined somewhere is reported as unbounded there).
PieceProof prove_piece(const std::vector<Expression>& curve, const BezierPiece& piece,
                       double tolerance, std::size_t max_cells);

}  // namespace pathstream::host::curves
