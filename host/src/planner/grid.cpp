// The lookahead grid: nodes along the path at known arc length, with tangent and curvature;
// stops at sharp corners, cusps and pen changes; the arc length -> point lookup.
#include "grid.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cubic.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kDegenerateMm = 1e-9;  // a segment with every control point this close is a point

double angle_between(const Vec& a, const Vec& b) {
    return std::acos(std::clamp(dot(a, b), -1.0, 1.0));
}

/// Unit tangent at u, well defined where q'(u) vanishes (degenerate handles, cusps): then the
/// tangent is taken a little towards `side` (+1: larger u).
Vec unit_tangent(const Cubic& c, double u, double size, int side) {
    Vec d = c.d1(u);
    double n = norm(d);
    if (n <= 1e-9 * size) {
        const double v = std::clamp(u + side * 1e-4, 0.0, 1.0);
        d = c.d1(v);
        n = norm(d);
        if (n <= 1e-12 * size) {  // still flat: the chord
            d = sub(c.p[3], c.p[0]);
            n = norm(d);
        }
    }
    return n > 0 ? scaled(d, 1 / n) : Vec{};
}

/// Curvature vector d2q/dl2 at u (evaluated slightly inside the segment where q' vanishes).
Vec curvature(const Cubic& c, double u, double size, int side) {
    double w = u;
    Vec d = c.d1(w);
    if (norm(d) <= 1e-7 * size) {
        w = std::clamp(u + side * 1e-3, 0.0, 1.0);
        d = c.d1(w);
    }
    const double n2 = dot(d, d);
    if (n2 <= 0) return Vec{};
    const Vec dd = c.d2(w);
    const double along = dot(dd, d) / n2;
    Vec k{};
    for (std::size_t i = 0; i < kAxesMax; ++i) k[i] = (dd[i] - along * d[i]) / n2;
    return k;
}

/// An interval of a segment's parameter that segment_nodes still has to examine.
struct NodeInterval {
    double a, b;
    Vec ta, tb;  ///< tangent after a, before b
};

/// Parameters of the grid nodes along one segment: uniform in u, then bisected wherever the
/// tangent turns by more than max_turn between neighbours or may turn by more inside the
/// interval (the bound of turns_inside below). A turn above 90 degrees inside an
/// interval shorter than 1e-7 in u is a cusp: its parameter goes to `cusps`. The parameters
/// go to `out` (cleared first); `stack` is scratch. Both are the caller's, so that their
/// storage is reused from segment to segment.
void segment_nodes(const Cubic& c, double length, const PlanOptions& o, std::vector<double>& cusps,
                   std::vector<double>& out, std::vector<NodeInterval>& stack) {
    const double size = c.size();
    std::size_t k = std::max<std::size_t>(o.min_nodes_per_segment, 1);
    if (o.grid_step > 0) {
        k = std::max<std::size_t>(
            k, static_cast<std::size_t>(std::ceil(std::min(length / o.grid_step, 1e6))));
    }
    // A node's tangent on either side (they differ only where q' vanishes), computed once.
    struct Sides {
        Vec before, after;
    };
    const auto sides = [&](double u) {
        const Vec d = c.d1(u);
        const double n = norm(d);
        if (n > 1e-9 * size) {
            const Vec t = scaled(d, 1 / n);
            return Sides{t, t};
        }
        return Sides{unit_tangent(c, u, size, -1), unit_tangent(c, u, size, +1)};
    };
    // turn > max_turn, and turn > 90 degrees, compared as cosines.
    const double cos_max_turn = std::cos(std::clamp(o.max_turn, 0.0, kPi));
    // The end tangents alone miss a turn that goes out and comes back inside the interval (a
    // loop a few micrometres across, whose caps the nodes would not see). q' over [a, b] is a
    // quadratic Bezier with control points q'(a), q'(a) + (b - a) q''(a) / 2, q'(b), and every
    // tangent inside lies in the cone they span: if the two angles of that control polygon
    // (taken from the end tangents) add up to at most max_turn, no two tangents inside differ
    // by more.
    const auto turns_inside = [&](double a, double b, const Vec& ta, const Vec& tb) {
        const Vec d1 = c.d1(a), d2 = c.d2(a);
        Vec h1{};
        for (std::size_t i = 0; i < kAxesMax; ++i) h1[i] = d1[i] + 0.5 * (b - a) * d2[i];
        const double n1 = norm(h1);
        if (!(n1 > 0)) return false;
        // cos(alpha + beta) against cos(max_turn), without acos (this runs for every interval);
        // an angle over 90 degrees bisects at once, so alpha + beta < pi below.
        const double ca = std::clamp(dot(ta, h1) / n1, -1.0, 1.0),
                     cb = std::clamp(dot(h1, tb) / n1, -1.0, 1.0);
        if (ca < 0 || cb < 0) return true;
        return ca * cb - std::sqrt((1 - ca * ca) * (1 - cb * cb)) < cos_max_turn;
    };
    out.clear();
    stack.clear();  // intervals still to examine, last first
    Sides right = sides(1.0);
    for (std::size_t i = k; i-- > 0;) {
        const double a = static_cast<double>(i) / static_cast<double>(k);
        const double b = i + 1 == k ? 1.0 : static_cast<double>(i + 1) / static_cast<double>(k);
        const Sides left = sides(a);
        stack.push_back({a, b, left.after, right.before});
        right = left;
    }
    out.push_back(0.0);
    while (!stack.empty()) {
        const NodeInterval in = stack.back();
        stack.pop_back();
        const double cos_turn = std::clamp(dot(in.ta, in.tb), -1.0, 1.0);
        if (cos_turn < cos_max_turn || turns_inside(in.a, in.b, in.ta, in.tb)) {
            if (in.b - in.a > 1e-7) {
                const double m = 0.5 * (in.a + in.b);
                const Sides mid = sides(m);
                stack.push_back({m, in.b, mid.after, in.tb});
                stack.push_back({in.a, m, in.ta, mid.before});
                continue;
            }
            if (cos_turn < 0) cusps.push_back(norm(c.d1(in.a)) < norm(c.d1(in.b)) ? in.a : in.b);
        }
        out.push_back(in.b);
    }
    // A cusp exactly on a node (q' vanishes there, as where a Bezier handle doubles back on a
    // straight line) leaves both neighbouring intervals without a turn, because each end's
    // tangent is taken on the interval's own side: compare the two sides at the node.
    for (std::size_t i = 1; i + 1 < out.size(); ++i) {
        if (norm(c.d1(out[i])) > 1e-9 * size) continue;
        if (angle_between(unit_tangent(c, out[i], size, -1), unit_tangent(c, out[i], size, +1)) >
            0.5 * kPi) {
            cusps.push_back(out[i]);
        }
    }
}

struct Builder {
    const std::vector<BezierSegment>& segments;
    const MachineProfile& profile;
    const PlanOptions& options;
    PathGrid out;
    double lambda = 0;
    double kappa_stop_ = 0;
    std::vector<double> nodes_, cusps_;    ///< segment_nodes' output and cusps, storage reused
    std::vector<NodeInterval> intervals_;  ///< segment_nodes' scratch

    void add_node(std::uint32_t seg, double u, double lam, const Vec& q, const Vec& t, const Vec& k,
                  double feed) {
        Grid& g = out.grid;
        g.lambda.push_back(lam);
        g.u.push_back(u);
        g.seg.push_back(seg);
        g.q.push_back(q);
        g.tangent.push_back(t);
        g.curvature.push_back(k);
        g.feed.push_back(feed);
        g.corner_jump.push_back(Vec{});
    }

    void close_piece(Run& run, std::size_t first, std::size_t last, double feed) {
        Piece p;
        p.first = first;
        p.last = last;
        p.run = out.runs.size();
        p.feed = feed;
        run.pieces.push_back(out.pieces.size());
        out.pieces.push_back(p);
    }

    void build_run(std::size_t first_seg, std::size_t last_seg) {
        Grid& g = out.grid;
        Run run;
        run.pen_down = segments[first_seg].pen_down;
        run.subpath = segments[first_seg].subpath;
        run.first_segment = first_seg;
        run.last_segment = last_seg;
        run.pause_before = segments[first_seg].pause_before;
        run.dwell_before = segments[first_seg].dwell_before;
        run.dwell_pen_down = segments[first_seg].dwell_pen_down;
        run.outputs = segments[first_seg].outputs;
        run.pause_outputs = segments[first_seg].pause_outputs;
        run.start = out.cubics[first_seg].p[0];
        run.end = out.cubics[last_seg].p[3];
        const double feed =
            run.pen_down
                ? (segments[first_seg].feed > 0 ? segments[first_seg].feed : profile.feed)
                : (segments[first_seg].feed > 0 ? segments[first_seg].feed : profile.travel_feed);
        std::size_t piece_first = g.size();
        bool any = false;
        for (std::size_t s = first_seg; s <= last_seg; ++s) {
            const Cubic& c = out.cubics[s];
            const double size = c.size();
            if (size < kDegenerateMm) continue;
            const double length = arc_length(c, 0, 0.5) + arc_length(c, 0.5, 1);
            if (length < kDegenerateMm) continue;
            (run.pen_down ? out.pen_down_length : out.travel_length) += length;
            std::vector<double>& cusps = cusps_;
            cusps.clear();
            segment_nodes(c, length, options, cusps, nodes_, intervals_);
            const std::vector<double>& us = nodes_;
            const std::size_t seg_first = g.size();
            double lam = lambda;
            for (std::size_t i = 0; i < us.size(); ++i) {
                if (i > 0) lam += arc_length(c, us[i - 1], us[i]);
                const int side = i + 1 == us.size() ? -1 : +1;
                Vec q = c.point(us[i]);
                add_node(static_cast<std::uint32_t>(s), us[i], lam, q,
                         unit_tangent(c, us[i], size, side), curvature(c, us[i], size, side), feed);
            }
            if (any) {  // the joint with the previous segment of this run
                const std::size_t a = seg_first - 1, b = seg_first;
                const double turn = angle_between(g.tangent[a], g.tangent[b]);
                const bool sharp =
                    norm(g.curvature[a]) > kappa_stop_ || norm(g.curvature[b]) > kappa_stop_;
                if (turn > options.corner_stop_angle || sharp || segments[s].stop_before) {
                    close_piece(run, piece_first, a, feed);
                    piece_first = b;
                } else if (turn > 1e-9) {
                    g.corner_jump[a] = g.corner_jump[b] = sub(g.tangent[b], g.tangent[a]);
                }
            }
            // Curvature peaks too sharp to cross: where the speed cap sqrt(a / kappa) is below
            // one tick of acceleration (kappa > 1 / (a T^2), smallest axis), the motion stops, as
            // at a cusp.
            for (std::size_t n = seg_first + 1; n + 1 < g.size(); ++n) {
                const double kn = norm(g.curvature[n]);
                if (kn > kappa_stop_ && kn >= norm(g.curvature[n - 1]) &&
                    kn >= norm(g.curvature[n + 1])) {
                    cusps.push_back(g.u[n]);
                }
            }
            std::sort(cusps.begin(), cusps.end());
            // Cusps inside the segment: the piece ends at the node nearest the cusp and the
            // next one starts there.
            for (double cu : cusps) {
                std::size_t best = seg_first;
                for (std::size_t n = seg_first; n < g.size(); ++n) {
                    if (std::fabs(g.u[n] - cu) < std::fabs(g.u[best] - cu)) best = n;
                }
                if (best > piece_first && best + 1 < g.size() &&
                    (out.pieces.empty() || run.pieces.empty() || out.pieces.back().last != best)) {
                    g.curvature[best] = Vec{};
                    close_piece(run, piece_first, best, feed);
                    piece_first = best;
                }
            }
            lambda = lam;
            any = true;
        }
        if (!any) {  // nothing but points: a piece of zero length where the run is
            add_node(static_cast<std::uint32_t>(first_seg), 0, lambda, run.start, Vec{}, Vec{},
                     feed);
        }
        close_piece(run, piece_first, g.size() - 1, feed);
        out.runs.push_back(std::move(run));
    }
};

}  // namespace

Cubic to_cubic(const BezierSegment& s) {
    Cubic c;
    c.axes = std::min(s.p[0].size(), kAxesMax);
    for (std::size_t k = 0; k < 4; ++k) {
        for (std::size_t i = 0; i < s.p[k].size() && i < kAxesMax; ++i) c.p[k][i] = s.p[k][i];
    }
    return c;
}

double speed_at(const Cubic& c, double u) {
    const Vec d = c.d1(u);
    double d2 = 0;
    for (std::size_t a = 0; a < c.axes; ++a) d2 += d[a] * d[a];
    return std::sqrt(d2);
}

double arc_length(const Cubic& c, double u0, double u1) {
    static constexpr double x[5] = {0.0, -0.5384693101056831, 0.5384693101056831,
                                    -0.9061798459386640, 0.9061798459386640};
    static constexpr double w[5] = {0.5688888888888889, 0.4786286704993665, 0.4786286704993665,
                                    0.2369268850561891, 0.2369268850561891};
    const double h = 0.5 * (u1 - u0), m = 0.5 * (u0 + u1);
    double s = 0;
    for (int i = 0; i < 5; ++i) s += w[i] * speed_at(c, m + h * x[i]);
    return s * h;
}

PathGrid build_grid(const std::vector<BezierSegment>& segments, const MachineProfile& profile,
                    const PlanOptions& options, std::size_t first_index) {
    const std::size_t axes = profile.axes.size();
    Builder b{segments, profile, options, {}, 0, 0, {}, {}, {}};
    double a_min = 0;
    for (const auto& a : profile.axes)
        a_min = a_min == 0 ? a.max_acceleration : std::min(a_min, a.max_acceleration);
    const double tick = 1 / profile.tick_hz;
    b.kappa_stop_ = a_min > 0 ? 1 / (a_min * tick * tick) : std::numeric_limits<double>::infinity();
    // With a jerk limit (docs/planner.md §12) also where the jerk cap kappa^2 s^3 <= j / 4 is below
    // that speed, a T: kappa > sqrt(j / 4 / (a T)^3), smallest limits.
    double j_min = 0;
    for (const auto& a : profile.axes) {
        if (a.max_jerk > 0) j_min = j_min == 0 ? a.max_jerk : std::min(j_min, a.max_jerk);
    }
    if (j_min > 0 && a_min > 0) {
        b.kappa_stop_ =
            std::min(b.kappa_stop_, std::sqrt(0.25 * j_min / std::pow(a_min * tick, 3)));
    }
    b.out.grid.axes = axes;
    for (VecArray* v :
         {&b.out.grid.q, &b.out.grid.tangent, &b.out.grid.curvature, &b.out.grid.corner_jump}) {
        v->set_axes(axes);
    }
    for (std::size_t s = 0; s < segments.size(); ++s) {
        for (const auto& p : segments[s].p) {
            if (p.size() != axes) {
                std::ostringstream m;
                m << "segment " << first_index + s << " (subpath " << segments[s].subpath
                  << ") has " << p.size() << " coordinates but the machine has " << axes << " axes";
                throw PlanError(m.str());
            }
            for (double x : p) {
                if (!std::isfinite(x)) {
                    throw PlanError("segment " + std::to_string(first_index + s) +
                                    " has a non-finite coordinate");
                }
            }
        }
        if (s == 0) {
            b.out.cubics.reserve(segments.size());
            b.out.cubic_size.reserve(segments.size());
        }
        b.out.cubics.push_back(to_cubic(segments[s]));
        b.out.cubic_size.push_back(b.out.cubics.back().size());
        if (s > 0) {
            const double gap = norm(sub(b.out.cubics[s].p[0], b.out.cubics[s - 1].p[3]));
            if (gap > 1e-6) {
                std::ostringstream m;
                m << "segment " << first_index + s << " (subpath " << segments[s].subpath
                  << ") starts " << gap << " mm away from where segment " << first_index + s - 1
                  << " ends: the path must be continuous";
                throw PlanError(m.str());
            }
        }
    }
    for (std::size_t s = 0; s < segments.size();) {
        std::size_t e = s;
        while (e + 1 < segments.size() && segments[e + 1].pen_down == segments[s].pen_down &&
               segments[e + 1].subpath == segments[s].subpath) {
            ++e;
        }
        b.build_run(s, e);
        s = e + 1;
    }
    Grid& g = b.out.grid;
    const std::size_t n = g.size();
    g.param_pace.resize(n);
    g.curvature_norm.resize(n);
    g.corner.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
        const double speed = speed_at(b.out.cubics[g.seg[k]], g.u[k]);
        g.param_pace[k] = speed > 0 ? 1 / speed : 0;
        g.curvature_norm[k] = norm(g.curvature[k]);
        g.corner[k] = norm(g.corner_jump[k]) > 0 ? 1 : 0;
    }
    return std::move(b.out);
}

PathAt path_at(const PathGrid& pg, const Piece& piece, double lambda, std::size_t& hint,
               bool precise) {
    const Grid& g = pg.grid;
    PathAt r;
    if (piece.first == piece.last) {
        r.q = g.q[piece.first];
        r.t = g.tangent[piece.first];
        return r;
    }
    // Interval [k, k+1] of positive length with lambda[k] <= lambda < lambda[k+1].
    std::size_t k = std::clamp(hint, piece.first, piece.last - 1);
    for (std::size_t steps = 0; g.lambda[k] > lambda && k > piece.first && steps < 16; ++steps) --k;
    if (g.lambda[k] > lambda) {
        const auto it = std::upper_bound(
            g.lambda.begin() + static_cast<std::ptrdiff_t>(piece.first),
            g.lambda.begin() + static_cast<std::ptrdiff_t>(piece.last) + 1, lambda);
        k = static_cast<std::size_t>(it - g.lambda.begin());
        k = k == 0 ? 0 : k - 1;
    } else {
        std::size_t steps = 0;
        while (k + 1 < piece.last && g.lambda[k + 1] <= lambda && ++steps < 64) ++k;
        if (k + 1 < piece.last && g.lambda[k + 1] <= lambda) {
            const auto it = std::upper_bound(
                g.lambda.begin() + static_cast<std::ptrdiff_t>(k),
                g.lambda.begin() + static_cast<std::ptrdiff_t>(piece.last) + 1, lambda);
            k = static_cast<std::size_t>(it - g.lambda.begin()) - 1;
        }
    }
    k = std::clamp(k, piece.first, piece.last - 1);
    while (k > piece.first && g.lambda[k + 1] <= g.lambda[k]) --k;  // skip a zero-length joint link
    hint = k;
    const double l0 = g.lambda[k], l1 = g.lambda[k + 1];
    if (!(l1 > l0) || g.seg[k] != g.seg[k + 1]) {
        r.q = g.q[k + 1];
        r.t = g.tangent[k + 1];
        return r;
    }
    const Cubic& c = pg.cubics[g.seg[k]];
    const double u0 = g.u[k], u1 = g.u[k + 1];
    const double target = std::clamp(lambda - l0, 0.0, l1 - l0);
    // Newton on the arc length, kept inside [lo, hi] by bisection, from u(lambda)'s cubic
    // Hermite interpolant on the interval (du/dlambda = 1 / |q'(u)| at its ends), which is
    // usually so close that one step lands within the tolerance: the step is then taken
    // without another quadrature when its quadratic error term, |q''| e^2 / 2 for a step of e
    // in u, is far below the tolerance.
    const double tolerance = 1e-12 * (1 + l1);
    const double h = l1 - l0, w = target / h;
    const double p0 = g.param_pace[k], p1 = g.param_pace[k + 1];
    double u;
    if (p0 > 0 && p1 > 0) {
        const double w2 = w * w, w3 = w2 * w;
        u = (2 * w3 - 3 * w2 + 1) * u0 + (w3 - 2 * w2 + w) * h * p0 + (-2 * w3 + 3 * w2) * u1 +
            (w3 - w2) * h * p1;
        if (!(u > u0 && u < u1)) u = u0 + (u1 - u0) * w;
    } else {
        u = u0 + (u1 - u0) * w;
    }
    double lo = u0, hi = u1;
    for (int it = 0; it < (precise ? 12 : 0); ++it) {
        const double f = arc_length(c, u0, u) - target;
        if (std::fabs(f) < tolerance) break;
        if (f > 0)
            hi = u;
        else
            lo = u;
        const double speed = speed_at(c, u);
        double next = speed > 0 ? u - f / speed : 0.5 * (lo + hi);
        if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
        const double e = next - u;
        u = next;
        if (next - lo > 0 && hi - next > 0 && speed > 0 &&
            0.5 * norm(c.d2(u)) * e * e < 0.1 * tolerance && std::fabs(f) < 1e-3 * h) {
            break;
        }
    }
    r.q = c.point(u);
    const Vec d = c.d1(u);
    const double n = norm(d);
    if (n > 1e-9 * pg.cubic_size[g.seg[k]]) {
        r.t = scaled(d, 1 / n);
    } else {  // at a degenerate point: interpolate the node tangents
        const double wl = (lambda - l0) / (l1 - l0);
        for (std::size_t i = 0; i < kAxesMax; ++i)
            r.t[i] = (1 - wl) * g.tangent[k][i] + wl * g.tangent[k + 1][i];
        const double m = norm(r.t);
        if (m > 0) r.t = scaled(r.t, 1 / m);
    }
    return r;
}

}  // namespace pathstream::host::planner_detail
