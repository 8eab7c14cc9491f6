// Adaptive Hermite fitting: samples first (cheap, rejects most pieces that are too long), then
// the interval proof, which is what a piece is accepted on.
#include "fit_function.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "evaluate.hpp"
#include "piece_proof.hpp"

namespace pathstream::host::curves {

namespace {

// A piece is sent to the proof only when its samples are below this share of the tolerance:
// the rest is the room the proof's overestimate needs to succeed with few cells.
constexpr double kSampleShare = 0.7;
constexpr int kSamples = 8;
// Halvings of the whole range before a piece counts as too short to split further.
constexpr int kMaxDepth = 60;
// Beyond this a coordinate is no drawing (1000 km); refusing it early also keeps a pole, where
// the curve runs off to infinity, from costing the whole piece budget first.
constexpr double kMaxCoordinate = 1e9;

std::string number(double v) {
    std::ostringstream s;
    s << std::setprecision(15) << v;
    return s.str();
}

std::string axis_name(std::size_t k) {
    static const char* const kNames[] = {"x", "y", "z"};
    return k < 3 ? kNames[k] : "coordinate " + std::to_string(k + 1);
}

void check_value(std::size_t k, double t, double v) {
    if (!std::isfinite(v))
        throw FitError(axis_name(k) + " is not finite at t=" + number(t) + " (" + number(v) + ")");
    if (std::fabs(v) > kMaxCoordinate)
        throw FitError(axis_name(k) + " is " + number(v) + " mm at t=" + number(t) +
                       ", beyond the " + number(kMaxCoordinate) + " mm a curve may reach");
}

struct End {
    double t = 0;
    std::vector<double> value;
    std::vector<double> slope;
};

End end_at(const FunctionCurve& curve, double t) {
    End end{t, {}, {}};
    for (std::size_t k = 0; k < curve.coordinates.size(); ++k) {
        const Dual<double> d = evaluate_dual(curve.coordinates[k], t);
        if (!std::isfinite(d.v))
            throw FitError(axis_name(k) + " is not finite at t=" + number(t) + " (" + number(d.v) +
                           ")");
        if (!std::isfinite(d.d))
            throw FitError("the derivative of " + axis_name(k) + " is not finite at t=" +
                           number(t) + " (" + number(d.d) + "): the curve has no tangent there");
        end.value.push_back(d.v);
        end.slope.push_back(d.d);
    }
    return end;
}

BezierPiece hermite(const End& left, const End& right) {
    BezierPiece piece{left.t, right.t, {}};
    const double third = (right.t - left.t) / 3;
    for (std::size_t k = 0; k < left.value.size(); ++k) {
        piece.control.push_back({left.value[k], left.value[k] + third * left.slope[k],
                                 right.value[k] - third * right.slope[k], right.value[k]});
    }
    return piece;
}

double bezier_at(const std::array<double, 4>& p, double u) {
    const double v = 1 - u;
    return v * v * v * p[0] + 3 * v * v * u * p[1] + 3 * v * u * u * p[2] + u * u * u * p[3];
}

// The largest error at the samples; throws where the curve is not finite.
double sampled_error(const FunctionCurve& curve, const BezierPiece& piece) {
    double worst = 0;
    for (int i = 1; i < kSamples; ++i) {
        const double u = static_cast<double>(i) / kSamples;
        const double t = piece.a + (piece.b - piece.a) * u;
        double sum = 0;
        for (std::size_t k = 0; k < curve.coordinates.size(); ++k) {
            const double c = evaluate(curve.coordinates[k], t);
            check_value(k, t, c);
            const double e = c - bezier_at(piece.control[k], u);
            sum += e * e;
        }
        worst = std::max(worst, std::sqrt(sum));
    }
    return worst;
}

void check(const FunctionCurve& curve, double tolerance) {
    if (curve.coordinates.empty() || curve.coordinates.size() > 8)
        throw FitError("a function curve needs 1 to 8 coordinates, got " +
                       std::to_string(curve.coordinates.size()));
    for (const Expression& e : curve.coordinates) {
        if (e.nodes.empty()) throw FitError("a coordinate has no expression");
    }
    if (!std::isfinite(curve.t0) || !std::isfinite(curve.t1))
        throw FitError("the t range [" + number(curve.t0) + ", " + number(curve.t1) +
                       "] must be finite");
    if (!(curve.t0 < curve.t1))
        throw FitError("the t range [" + number(curve.t0) + ", " + number(curve.t1) +
                       "] must increase (t1 > t0)");
    if (!std::isfinite(tolerance) || !(tolerance > 0))
        throw FitError("the tolerance " + number(tolerance) + " mm must be positive and finite");
}

void append(FittedCurve& fit, const BezierPiece& piece) {
    const std::size_t axes = piece.control.size();
    for (int j = fit.points.empty() ? 0 : 1; j < 4; ++j) {
        PathPoint p(axes);
        for (std::size_t k = 0; k < axes; ++k) p[k] = piece.control[k][static_cast<std::size_t>(j)];
        fit.points.push_back(std::move(p));
    }
    if (fit.breaks.empty()) fit.breaks.push_back(piece.a);
    fit.breaks.push_back(piece.b);
}

struct Span {
    double a;
    double b;
    int depth;
};

}  // namespace

FittedCurve fit_function_curve_pieces(const FunctionCurve& curve, double tolerance_mm,
                                      const FitLimits& limits) {
    check(curve, tolerance_mm);
    FittedCurve fit;
    FitFigures& figures = fit.figures;
    End left = end_at(curve, curve.t0);
    // Spans still to fit, the leftmost last: the one popped always starts where the chain ends.
    std::vector<Span> spans{{curve.t0, curve.t1, 0}};
    while (!spans.empty()) {
        const Span span = spans.back();
        spans.pop_back();
        const End right = end_at(curve, span.b);
        const BezierPiece piece = hermite(left, right);
        const double sampled = sampled_error(curve, piece);
        PieceProof proof;
        if (sampled <= kSampleShare * tolerance_mm) {
            const std::size_t room = limits.max_cells - std::min(limits.max_cells, figures.cells);
            proof = prove_piece(curve.coordinates, piece, tolerance_mm,
                                std::min(limits.max_cells_per_piece, room));
            figures.cells += proof.cells;
            if (proof.proven) {
                if (figures.pieces == limits.max_pieces)
                    throw FitError("the curve needs more than " +
                                   std::to_string(limits.max_pieces) + " pieces at tolerance " +
                                   number(tolerance_mm) + " mm");
                append(fit, piece);
                fit.bounds.push_back(proof.bound);
                ++figures.pieces;
                figures.largest_bound = std::max(figures.largest_bound, proof.bound);
                figures.largest_sampled_error = std::max(figures.largest_sampled_error, sampled);
                left = right;
                continue;
            }
            if (figures.cells >= limits.max_cells)
                throw FitError("proving the tolerance needs more than " +
                               std::to_string(limits.max_cells) +
                               " interval cells (near t=" + number(proof.failed_at) + ")");
        }
        const double m = span.a + (span.b - span.a) / 2;
        if (span.depth >= kMaxDepth || !(span.a < m && m < span.b)) {
            if (proof.unbounded)
                throw FitError("the curve's derivative is unbounded or undefined near t=" +
                               number(proof.failed_at) + ": its error cannot be bounded there");
            throw FitError("the curve cannot be fitted within " + number(tolerance_mm) +
                           " mm near t=" + number(m) + " (not even by pieces " +
                           number(span.b - span.a) + " long in t): is it discontinuous there?");
        }
        spans.push_back({m, span.b, span.depth + 1});
        spans.push_back({span.a, m, span.depth + 1});
    }
    return fit;
}

std::vector<PathPoint> fit_function_curve(const FunctionCurve& curve, double tolerance_mm,
                                          FitFigures* figures, const FitLimits& limits) {
    FittedCurve fit = fit_function_curve_pieces(curve, tolerance_mm, limits);
    if (figures != nullptr) *figures = fit.figures;
    return std::move(fit.points);
}

}  // namespace pathstream::host::curves
