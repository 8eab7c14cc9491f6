// A first-order (mean-value) bound per cell: cheap, and its overestimate shrinks with the
// square of the cell's width, so halving the cells that fail converges wherever the true
// error is below the tolerance by some margin.
#include "piece_proof.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "evaluate.hpp"
#include "interval.hpp"

namespace pathstream::host::curves {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The cubic Bernstein polynomial at u (an interval), every operation rounded outward.
Interval bezier(const std::array<double, 4>& p, const Interval& u) {
    const Interval v = Interval(1.0) - u;
    return Interval(p[0]) * v * v * v + Interval(3.0) * Interval(p[1]) * v * v * u +
           Interval(3.0) * Interval(p[2]) * v * u * u + Interval(p[3]) * u * u * u;
}

// Blossom of the quadratic with Bernstein values q at (u, w): q(u) when w = u; the middle
// Bezier value of the quadratic restricted to [u, w] otherwise.
Interval blossom(const std::array<Interval, 3>& q, double u, double w) {
    const Interval iu(u), iw(w), one(1.0);
    return q[0] * (one - iu) * (one - iw) + q[1] * ((one - iu) * iw + iu * (one - iw)) +
           q[2] * iu * iw;
}

// The derivative d/du of the cubic over u in [lo, hi]: the hull of the restricted quadratic's
// three Bezier values, which contains its range exactly (up to rounding).
Interval derivative_range(const std::array<double, 4>& p, double lo, double hi) {
    const std::array<Interval, 3> q{Interval(3.0) * (Interval(p[1]) - Interval(p[0])),
                                    Interval(3.0) * (Interval(p[2]) - Interval(p[1])),
                                    Interval(3.0) * (Interval(p[3]) - Interval(p[2]))};
    return hull(hull(blossom(q, lo, lo), blossom(q, lo, hi)), blossom(q, hi, hi));
}

// The bound of |e| over [lo, hi] (mm); infinite when something is unbounded or undefined.
double cell_bound(const std::vector<Expression>& curve, const BezierPiece& piece, double lo,
                  double hi, bool& unbounded) {
    const double m = lo + (hi - lo) / 2;
    const double radius =
        std::max((Interval(m) - Interval(lo)).hi, (Interval(hi) - Interval(m)).hi);
    const Interval length = Interval(piece.b) - Interval(piece.a);
    const Interval u_cell = (Interval(lo, hi) - Interval(piece.a)) / length;
    const Interval u_mid = (Interval(m) - Interval(piece.a)) / length;
    Interval sum(0.0);
    for (std::size_t k = 0; k < curve.size(); ++k) {
        const Interval slope = evaluate_dual(curve[k], Interval(lo, hi)).d;
        const Interval at_mid = evaluate_dual(curve[k], Interval(m)).v;
        const Interval piece_slope =
            derivative_range(piece.control[k], u_cell.lo, u_cell.hi) / length;
        const double e_mid = (at_mid - bezier(piece.control[k], u_mid)).magnitude();
        const double e_slope = (slope - piece_slope).magnitude();
        if (!std::isfinite(e_mid) || !std::isfinite(e_slope)) {
            unbounded = true;
            return kInf;
        }
        sum = sum + sqr(Interval(e_mid) + Interval(e_slope) * Interval(radius));
    }
    // Only the upper end counts: the lower one may dip below 0 by rounding, where sqrt is
    // undefined.
    return sqrt(Interval(sum.hi)).hi;
}

}  // namespace

PieceProof prove_piece(const std::vector<Expression>& curve, const BezierPiece& piece,
                       double tolerance, std::size_t max_cells) {
    PieceProof proof;
    std::vector<std::pair<double, double>> cells{{piece.a, piece.b}};
    while (!cells.empty()) {
        const auto [lo, hi] = cells.back();
        cells.pop_back();
        bool unbounded = false;
        const double bound = cell_bound(curve, piece, lo, hi, unbounded);
        ++proof.cells;
        if (bound <= tolerance) {
            proof.bound = std::max(proof.bound, bound);
            continue;
        }
        const double m = lo + (hi - lo) / 2;
        if (proof.cells + cells.size() + 2 > max_cells || !(lo < m && m < hi)) {
            proof.failed_at = m;
            proof.unbounded = unbounded;
            return proof;
        }
        cells.emplace_back(m, hi);
        cells.emplace_back(lo, m);
    }
    proof.proven = true;
    return proof;
}

}  // namespace pathstream::host::curves
