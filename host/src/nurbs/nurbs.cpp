// NURBS -> cubic Beziers: Boehm knot insertion to Bezier spans in homogeneous coordinates,
// then exact degree raising or adaptive Hermite cubics (docs/formats.md, "NURBS").
#include "nurbs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace pathstream::host::nurbs {

namespace {

using Point = std::vector<double>;  // homogeneous: w·x, w·y, ..., w

constexpr int kSamplesPerPiece = 32;
constexpr int kMaxSplitDepth = 40;

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

Point lerp(const Point& a, const Point& b, double t) {
    Point r(a.size());
    for (std::size_t k = 0; k < a.size(); ++k) r[k] = (1 - t) * a[k] + t * b[k];
    return r;
}

// Inserts u once into the knots (Boehm; The NURBS Book, A5.1 with r = 1).
void insert_knot(std::vector<double>& knots, std::vector<Point>& points, int p, double u) {
    const std::size_t top = knots.size() - 1;
    std::size_t k = 0;
    while (k + 1 <= top && knots[k + 1] <= u) ++k;  // knots[k] <= u < knots[k + 1]
    const auto s = static_cast<std::size_t>(std::count(knots.begin(), knots.end(), u));
    const auto pp = static_cast<std::size_t>(p);
    std::vector<Point> next(points.size() + 1);
    for (std::size_t i = 0; i < next.size(); ++i) {
        if (i + pp <= k) {
            next[i] = points[i];
        } else if (i + s <= k) {
            const double alpha = (u - knots[i]) / (knots[i + pp] - knots[i]);
            next[i] = lerp(points[i - 1], points[i], alpha);
        } else {
            next[i] = points[i - 1];
        }
    }
    knots.insert(knots.begin() + static_cast<std::ptrdiff_t>(k + 1), u);
    points = std::move(next);
}

// The Bezier spans (p + 1 homogeneous points each) of the curve over its domain. Knot
// insertion is local: a span's Bezier points depend only on its p + 1 control points and 2p + 2
// knots, so each span is refined on a copy of those alone, O(p^3) per span and linear in the
// control points (refining the whole curve at once was quadratic: every insertion copied it).
std::vector<std::vector<Point>> bezier_spans(const Nurbs& c) {
    const auto p = static_cast<std::size_t>(c.degree);
    const std::size_t n = c.points.size();
    std::vector<Point> points(n);
    for (std::size_t i = 0; i < n; ++i) {
        const double w = c.weights.empty() ? 1.0 : c.weights[i];
        points[i] = c.points[i];
        for (double& x : points[i]) x *= w;
        points[i].push_back(w);
    }
    const auto count = [](const std::vector<double>& knots, double u) {
        return static_cast<std::size_t>(std::count(knots.begin(), knots.end(), u));
    };
    std::vector<std::vector<Point>> spans;
    for (std::size_t i = p; i < n; ++i) {
        const double a = c.knots[i], b = c.knots[i + 1];
        if (!(a < b)) continue;  // an empty span: a repeated knot
        std::vector<double> knots(c.knots.begin() + static_cast<std::ptrdiff_t>(i - p),
                                  c.knots.begin() + static_cast<std::ptrdiff_t>(i + p + 2));
        std::vector<Point> local(points.begin() + static_cast<std::ptrdiff_t>(i - p),
                                 points.begin() + static_cast<std::ptrdiff_t>(i + 1));
        while (count(knots, a) < p) insert_knot(knots, local, c.degree, a);
        while (count(knots, b) < p) insert_knot(knots, local, c.degree, b);
        // The last knot equal to the span's start: its p + 1 points end there.
        std::size_t k = 0;
        while (k + 1 < knots.size() && knots[k + 1] <= a) ++k;
        spans.emplace_back(local.begin() + static_cast<std::ptrdiff_t>(k - p),
                           local.begin() + static_cast<std::ptrdiff_t>(k + 1));
    }
    return spans;
}

// A rational Bezier span: point and derivative at t (de Casteljau in homogeneous form).
struct Span {
    std::vector<Point> pw;

    void eval(double t, Point& at, Point& d) const {
        std::vector<Point> level = pw;
        const std::size_t p = level.size() - 1;
        for (std::size_t r = 1; r < p; ++r) {
            for (std::size_t i = 0; i + r <= p; ++i) level[i] = lerp(level[i], level[i + 1], t);
        }
        const Point a = level[0], b = p >= 1 ? level[1] : level[0];
        const Point h = lerp(a, b, t);
        const std::size_t dim = h.size() - 1;
        const double w = h[dim];
        const double dw = static_cast<double>(p) * (b[dim] - a[dim]);
        at.assign(dim, 0);
        d.assign(dim, 0);
        for (std::size_t k = 0; k < dim; ++k) {
            at[k] = h[k] / w;
            d[k] = (static_cast<double>(p) * (b[k] - a[k]) - at[k] * dw) / w;
        }
    }
};

double distance(const Point& a, const Point& b) {
    double s = 0;
    for (std::size_t k = 0; k < a.size(); ++k) s += (a[k] - b[k]) * (a[k] - b[k]);
    return std::sqrt(s);
}

Point cubic_at(const std::array<Point, 4>& q, double t) {
    const double u = 1 - t;
    const double b[4] = {u * u * u, 3 * u * u * t, 3 * u * t * t, t * t * t};
    Point r(q[0].size(), 0);
    for (int i = 0; i < 4; ++i) {
        for (std::size_t k = 0; k < r.size(); ++k) r[k] += b[i] * q[static_cast<std::size_t>(i)][k];
    }
    return r;
}

class ChainBuilder {
public:
    ChainBuilder(double tolerance, std::size_t max_pieces)
        : tolerance_(tolerance), max_pieces_(max_pieces) {}

    void add(const std::array<Point, 4>& q) {
        bool moves = false;
        for (std::size_t i = 1; i < 4; ++i) moves = moves || q[i] != q[0];
        if (!moves) return;
        if (++pieces_ > max_pieces_) {
            throw std::length_error("NURBS curve needs more than " + std::to_string(max_pieces_) +
                                    " cubic pieces");
        }
        if (chain_.empty()) chain_.push_back(q[0]);
        for (std::size_t i = 1; i < 4; ++i) chain_.push_back(q[i]);
    }

    // A polynomial span of degree <= 3: its exact cubic.
    void exact(const std::vector<Point>& pw) {
        std::vector<Point> c;
        for (const Point& h : pw) c.emplace_back(h.begin(), h.end() - 1);  // weights all 1
        if (c.size() == 2) {
            add({c[0], lerp(c[0], c[1], 1.0 / 3), lerp(c[0], c[1], 2.0 / 3), c[1]});
        } else if (c.size() == 3) {
            add({c[0], lerp(c[0], c[1], 2.0 / 3), lerp(c[2], c[1], 2.0 / 3), c[2]});
        } else {
            add({c[0], c[1], c[2], c[3]});
        }
    }

    // Hermite cubics over [a, b], halved until within the tolerance.
    void approximate(const Span& s, double a, double b, int depth) {
        Point p0, d0, p3, d3;
        s.eval(a, p0, d0);
        s.eval(b, p3, d3);
        const double h = (b - a) / 3;
        Point c1 = p0, c2 = p3;
        for (std::size_t k = 0; k < p0.size(); ++k) {
            c1[k] += h * d0[k];
            c2[k] -= h * d3[k];
        }
        const std::array<Point, 4> q{p0, c1, c2, p3};
        double worst = 0;
        Point at, d;
        for (int j = 1; j < kSamplesPerPiece; ++j) {
            const double t = static_cast<double>(j) / kSamplesPerPiece;
            s.eval(a + (b - a) * t, at, d);
            worst = std::max(worst, distance(cubic_at(q, t), at));
        }
        // 0.9: leaves room for the error between the samples.
        if (worst <= 0.9 * tolerance_ || depth >= kMaxSplitDepth) {
            add(q);
            return;
        }
        const double mid = (a + b) / 2;
        approximate(s, a, mid, depth + 1);
        approximate(s, mid, b, depth + 1);
    }

    std::vector<PathPoint> finish() { return std::move(chain_); }

private:
    double tolerance_;
    std::size_t max_pieces_;
    std::size_t pieces_ = 0;
    std::vector<PathPoint> chain_;
};

}  // namespace

std::string nurbs_problem(const Nurbs& c) {
    if (c.degree < 1 || c.degree > kMaxDegree) {
        return "degree must be 1 to " + std::to_string(kMaxDegree) + ", got " +
               std::to_string(c.degree);
    }
    const auto p = static_cast<std::size_t>(c.degree);
    const std::size_t n = c.points.size();
    if (n < p + 1) {
        return "degree " + std::to_string(p) + " needs at least " + std::to_string(p + 1) +
               " control points, got " + std::to_string(n);
    }
    if (c.knots.size() != n + p + 1) {
        return "needs " + std::to_string(n + p + 1) + " knots (points + degree + 1), got " +
               std::to_string(c.knots.size());
    }
    if (!c.weights.empty() && c.weights.size() != n) {
        return "needs one weight per control point (" + std::to_string(n) + "), got " +
               std::to_string(c.weights.size());
    }
    for (double w : c.weights) {
        if (!(w > 0) || !std::isfinite(w))
            return "weight " + number(w) + " must be positive and finite";
    }
    for (std::size_t i = 0; i < c.knots.size(); ++i) {
        if (!std::isfinite(c.knots[i])) return "knots must be finite";
        if (i > 0 && c.knots[i] < c.knots[i - 1]) return "knots must not decrease";
    }
    if (!(c.knots[p] < c.knots[n]))
        return "the knots leave the curve no domain (knot[degree] must be below knot[points])";
    for (std::size_t i = 0; i < c.knots.size();) {
        std::size_t j = i;
        while (j < c.knots.size() && c.knots[j] == c.knots[i]) ++j;
        const double u = c.knots[i];
        const bool inside = u > c.knots[p] && u < c.knots[n];
        if (j - i > (inside ? p : p + 1)) {
            return "knot " + number(u) + " is repeated " + std::to_string(j - i) +
                   " times (at most " +
                   (inside ? "degree = " + std::to_string(p) + " inside the curve"
                           : "degree + 1 = " + std::to_string(p + 1) + " at its ends") +
                   ")";
        }
        i = j;
    }
    return {};
}

std::vector<double> clamped_uniform_knots(std::size_t points, int degree) {
    const auto p = static_cast<std::size_t>(degree);
    std::vector<double> knots;
    for (std::size_t i = 0; i <= p; ++i) knots.push_back(0);
    for (std::size_t i = 1; i + p < points; ++i) knots.push_back(static_cast<double>(i));
    const double last = static_cast<double>(points - p);
    for (std::size_t i = 0; i <= p; ++i) knots.push_back(last);
    return knots;
}

std::vector<PathPoint> nurbs_to_bezier(const Nurbs& curve, double tolerance,
                                       std::size_t max_pieces) {
    if (const std::string problem = nurbs_problem(curve); !problem.empty()) {
        throw std::invalid_argument("nurbs_to_bezier: " + problem);
    }
    const bool rational =
        !curve.weights.empty() && std::any_of(curve.weights.begin(), curve.weights.end(),
                                              [&](double w) { return w != curve.weights.front(); });
    ChainBuilder chain(tolerance, max_pieces);
    for (std::vector<Point>& span : bezier_spans(curve)) {
        if (!rational && curve.degree <= 3) {
            // Equal weights cancel: divide them out before the exact form.
            for (Point& h : span) {
                const double w = h.back();
                for (double& x : h) x /= w;
            }
            chain.exact(span);
        } else {
            chain.approximate(Span{span}, 0, 1, 0);
        }
    }
    return chain.finish();
}

}  // namespace pathstream::host::nurbs
