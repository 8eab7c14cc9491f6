// Function curves (host/src/curves): the first byte picks the t range and the tolerance, the
// rest is one expression per line (x, y, z; y defaults to t). Either an ExpressionError or a
// FitError, or a chain of finite points whose pieces are within their proven bounds at their
// midpoints. Budgets scale with the expression's size so that any input fits in well under a
// second under ASan.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "curves/evaluate.hpp"
#include "curves/fit_function.hpp"
#include "fuzz_support.hpp"

namespace {

using namespace pathstream::host::curves;

// The proof's work per input, in interval evaluations of one node; a cell also costs about 32
// such units per coordinate for the Bezier piece's enclosures.
constexpr std::size_t kWorkBudget = 150'000;
constexpr std::size_t kBezierWork = 32;

double bezier(const std::vector<pathstream::host::PathPoint>& p, std::size_t k, std::size_t axis,
              double u) {
    const double v = 1 - u;
    return v * v * v * p[3 * k][axis] + 3 * v * v * u * p[3 * k + 1][axis] +
           3 * v * u * u * p[3 * k + 2][axis] + u * u * u * p[3 * k + 3][axis];
}

void check_fit(const FunctionCurve& curve, double tolerance, const FittedCurve& fit) {
    using pathstream::fuzz::violated;
    const std::size_t pieces = fit.figures.pieces;
    if (pieces == 0 || fit.points.size() != 3 * pieces + 1 || fit.breaks.size() != pieces + 1 ||
        fit.bounds.size() != pieces)
        violated("chain sizes do not match the piece count");
    for (const auto& p : fit.points) {
        if (p.size() != curve.coordinates.size()) violated("a point of the wrong size");
        for (const double c : p) {
            if (!std::isfinite(c)) violated("a coordinate that is not finite");
        }
    }
    if (fit.breaks.front() != curve.t0 || fit.breaks.back() != curve.t1)
        violated("the breaks do not span the t range");
    for (std::size_t k = 0; k < pieces; ++k) {
        if (!(fit.breaks[k] < fit.breaks[k + 1])) violated("breaks that do not increase");
        if (!(fit.bounds[k] <= tolerance)) violated("a proven bound above the tolerance");
        const double t = fit.breaks[k] + (fit.breaks[k + 1] - fit.breaks[k]) / 2;
        double sum = 0, slack = 1e-9;
        for (std::size_t axis = 0; axis < curve.coordinates.size(); ++axis) {
            const double e =
                evaluate(curve.coordinates[axis], t) - bezier(fit.points, k, axis, 0.5);
            sum += e * e;
            // The double evaluation's own rounding: at most what the point enclosure spans.
            slack += evaluate_dual(curve.coordinates[axis], Interval(t)).v.width();
        }
        // A point enclosure that is not finite says nothing about the rounding: skip.
        if (std::isfinite(slack) && !(std::sqrt(sum) <= fit.bounds[k] + slack))
            violated("an error above its proven bound");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    static const double kRanges[8][2] = {
        {0, 1}, {0, 6.283185307179586}, {-1, 1}, {0, 10}, {-3, 3}, {0, 1e-3}, {1, 1e3}, {1, 1}};
    static const double kTolerances[4] = {0.1, 0.01, 0.001, 1e-5};
    const std::string text = pathstream::fuzz::text_of(data + 1, size - 1);
    std::vector<std::string> lines;
    std::size_t start = 0;
    while (lines.size() < 3) {
        const std::size_t end = text.find('\n', start);
        lines.push_back(text.substr(start, end == std::string::npos ? end : end - start));
        if (end == std::string::npos) break;
        start = end + 1;
    }
    if (lines.size() == 1) lines.push_back("t");
    FunctionCurve curve;
    curve.t0 = kRanges[data[0] & 7u][0];
    curve.t1 = kRanges[data[0] & 7u][1];
    const double tolerance = kTolerances[(data[0] >> 3) & 3u];
    try {
        std::size_t nodes = 0;
        for (const std::string& line : lines) {
            curve.coordinates.push_back(parse_expression(line));
            nodes += curve.coordinates.back().nodes.size();
        }
        const std::size_t work = nodes + kBezierWork * curve.coordinates.size();
        const FitLimits limits{64, std::max<std::size_t>(16, kWorkBudget / work), 4096};
        check_fit(curve, tolerance, fit_function_curve_pieces(curve, tolerance, limits));
    } catch (const ExpressionError& e) {
        if (std::string(e.what()).rfind("col ", 0) != 0)
            pathstream::fuzz::violated(std::string("message: ") + e.what());
    } catch (const FitError&) {
    } catch (const std::exception& e) {
        pathstream::fuzz::violated(std::string("neither ExpressionError nor FitError: ") +
                                   e.what());
    }
    return 0;
}
