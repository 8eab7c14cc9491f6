// Path -> cubic Bezier segments in millimetres (the planner's input), and Bezier evaluation.
#include "pathstream/host/geometry.hpp"

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

namespace pathstream::host {
namespace {

using Window = std::array<PointRef, 4>;

PathPoint combine(PointRef a, double wa, PointRef b, double wb) {
    PathPoint r(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) r[i] = wa * a[i] + wb * b[i];
    return r;
}

PathPoint reflect(PointRef end, PointRef next) {  // phantom point 2 end - next
    return combine(end, 2.0, next, -1.0);
}

/// Four-point windows of a uniform B-spline or Catmull-Rom subpath, as core_spans.cpp makes
/// them: open ends get phantom points 2 P0 - P1 and 2 Pm - Pm-1; closed subpaths are periodic.
/// Hands them to `visit` one at a time: a window list of a 10^6-point subpath is ~40 MB.
template <typename Visit>
void for_each_window(const PointList& pts, bool closed, Visit&& visit) {
    const std::size_t m = pts.size();
    if (closed) {
        for (std::size_t i = 0; i < m; ++i) {
            visit(Window{pts[(i + m - 1) % m], pts[i], pts[(i + 1) % m], pts[(i + 2) % m]});
        }
        return;
    }
    const PathPoint before = reflect(pts[0], pts[1]), after = reflect(pts[m - 1], pts[m - 2]);
    // The extended list: before, pts[0], ..., pts[m - 1], after (m + 2 points).
    const auto ext = [&](std::size_t i) {
        return i == 0 ? PointRef(before) : i == m + 1 ? PointRef(after) : pts[i - 1];
    };
    for (std::size_t i = 0; i + 3 < m + 2; ++i)
        visit(Window{ext(i), ext(i + 1), ext(i + 2), ext(i + 3)});
}

/// Weighted sum w0 Q0 + w1 Q1 + w2 Q2 + w3 Q3 of a window.
PathPoint weigh(const Window& q, double w0, double w1, double w2, double w3) {
    PathPoint r(q[0].size());
    for (std::size_t i = 0; i < r.size(); ++i) {
        r[i] = w0 * q[0][i] + w1 * q[1][i] + w2 * q[2][i] + w3 * q[3][i];
    }
    return r;
}

/// Bezier control points of a uniform cubic B-spline window: rows [1 4 1 0]/6, [0 4 2 0]/6,
/// [0 2 4 0]/6, [0 1 4 1]/6.
std::array<PathPoint, 4> bspline_to_bezier(const Window& q) {
    return {weigh(q, 1.0 / 6, 4.0 / 6, 1.0 / 6, 0), weigh(q, 0, 4.0 / 6, 2.0 / 6, 0),
            weigh(q, 0, 2.0 / 6, 4.0 / 6, 0), weigh(q, 0, 1.0 / 6, 4.0 / 6, 1.0 / 6)};
}

/// Bezier control points of a uniform Catmull-Rom window (P0..P3, curve from P1 to P2):
/// (P1, P1 + (P2 - P0)/6, P2 - (P3 - P1)/6, P2).
std::array<PathPoint, 4> catmull_rom_to_bezier(const Window& q) {
    return {q[1], weigh(q, -1.0 / 6, 1, 1.0 / 6, 0), weigh(q, 0, 1.0 / 6, 1, -1.0 / 6), q[2]};
}

/// A straight cubic from a to b with its handles at the thirds (uniform speed in u).
std::array<PathPoint, 4> straight(PointRef a, PointRef b) {
    return {a, combine(a, 2.0 / 3, b, 1.0 / 3), combine(a, 1.0 / 3, b, 2.0 / 3), b};
}

using Controls = std::array<PathPoint, 4>;

/// Hands a subpath's cubics to `emit` one at a time, with the joints shared exactly (not
/// merely to rounding: each segment's P0 is a copy of the previous P3) and a closed subpath
/// ending where it starts. One segment is held back until the next is known, so the whole
/// subpath is never held at once.
class JointSharer {
public:
    JointSharer(bool closed, const std::function<void(Controls&)>& emit)
        : closed_(closed), emit_(emit) {}

    void add(Controls&& c) {
        if (held_) {
            c[0] = pending_[3];
            emit_(pending_);
        } else {
            first_ = c[0];
        }
        pending_ = std::move(c);
        held_ = true;
    }
    /// The last segment (`last_end`: its end point, for open B-spline and Catmull-Rom ends).
    void finish(const PointRef* last_end) {
        if (!held_) return;
        if (last_end != nullptr) pending_[3] = last_end->vector();
        if (closed_) pending_[3] = first_;
        emit_(pending_);
        held_ = false;
    }

private:
    bool closed_;
    const std::function<void(Controls&)>& emit_;
    Controls pending_;
    PathPoint first_;
    bool held_ = false;
};

void subpath_segments(const Subpath& sp, std::size_t index,
                      const std::function<void(Controls&)>& emit) {
    const auto& pts = sp.points;
    const std::size_t m = pts.size();
    const auto too_few = [&](const char* need) {
        throw std::invalid_argument("subpath " + std::to_string(index) + ": " +
                                    basis_name(sp.basis) + " needs " + need + " points, got " +
                                    std::to_string(m));
    };
    JointSharer out(sp.closed, emit);
    switch (sp.basis) {
        case PathBasis::kBSpline:
        case PathBasis::kCatmullRom: {
            if (m < (sp.closed ? 3u : 2u)) too_few(sp.closed ? "at least 3" : "at least 2");
            bool first = true;
            for_each_window(pts, sp.closed, [&](const Window& w) {
                Controls c = sp.basis == PathBasis::kBSpline ? bspline_to_bezier(w)
                                                             : catmull_rom_to_bezier(w);
                if (first && !sp.closed)
                    c[0] = pts.front();  // the clamped start is exactly the first point
                first = false;
                out.add(std::move(c));
            });
            const PointRef last = pts.back();
            out.finish(sp.closed ? nullptr : &last);  // and the clamped end the last
            return;
        }
        case PathBasis::kBezier: {
            if (sp.closed ? (m < 3 || m % 3 != 0) : (m < 4 || m % 3 != 1))
                too_few(sp.closed ? "3k" : "3k + 1");
            const std::size_t count = sp.closed ? m / 3 : (m - 1) / 3;
            for (std::size_t i = 0; i < count; ++i) {
                out.add({pts[3 * i], pts[3 * i + 1], pts[3 * i + 2], pts[(3 * i + 3) % m]});
            }
            break;
        }
        case PathBasis::kPolyline: {
            if (m < (sp.closed ? 3u : 2u)) too_few(sp.closed ? "at least 3" : "at least 2");
            const std::size_t count = sp.closed ? m : m - 1;
            for (std::size_t i = 0; i < count; ++i) out.add(straight(pts[i], pts[(i + 1) % m]));
            break;
        }
    }
    out.finish(nullptr);
}

}  // namespace

void for_each_bezier_segment(const Path& path,
                             const std::function<void(const BezierSegment&)>& visit) {
    bool any = false;
    PathPoint last_end;
    for (std::size_t s = 0; s < path.subpaths.size(); ++s) {
        const Subpath& sp = path.subpaths[s];
        if (!sp.points.empty() && sp.points.axes() != path.axes) {  // a list's points have one size
            throw std::invalid_argument("subpath " + std::to_string(s) + ": a point has " +
                                        std::to_string(sp.points.axes()) +
                                        " coordinates, expected " + std::to_string(path.axes));
        }
        bool first = true;
        BezierSegment seg;
        seg.pen_down = true;
        seg.subpath = s;
        seg.feed = sp.feed;
        seg.blend_tolerance = sp.corner_mode != CornerMode::kBlend ? 0.0
                              : sp.blend_tolerance > 0             ? sp.blend_tolerance
                                                                   : -1.0;
        std::size_t joint = 0;  // index of the segment about to be visited
        auto next_stop = sp.stops.begin();
        const bool stops = sp.corner_mode == CornerMode::kExactStop;
        subpath_segments(sp, s, [&](Controls& c) {
            if (first && any) {  // straight pen-up travel from the last end point to this start
                BezierSegment travel;
                travel.p = straight(last_end, c[0]);
                travel.pen_down = false;
                travel.subpath = s;
                visit(travel);
            }
            seg.p = std::move(c);
            seg.pause_before = first && sp.pause_before;
            seg.dwell_before = first ? sp.dwell_before : 0;
            seg.dwell_pen_down = first && sp.dwell_pen_down;
            while (stops && next_stop != sp.stops.end() && *next_stop < joint) ++next_stop;
            seg.stop_before = stops && !first && next_stop != sp.stops.end() && *next_stop == joint;
            seg.segment = static_cast<std::uint32_t>(joint);
            ++joint;
            first = false;
            any = true;
            visit(seg);
            last_end = seg.p[3];
        });
    }
}

std::vector<BezierSegment> to_bezier_segments(const Path& path) {
    std::vector<BezierSegment> out;
    for_each_bezier_segment(path, [&](const BezierSegment& s) { out.push_back(s); });
    return out;
}

PathPoint bezier_point(const BezierSegment& s, double u) {
    const double v = 1 - u;
    PathPoint r(s.p[0].size());
    for (std::size_t i = 0; i < r.size(); ++i) {  // de Casteljau, each lerp exact at u = 0 and 1
        const double a = v * s.p[0][i] + u * s.p[1][i];
        const double b = v * s.p[1][i] + u * s.p[2][i];
        const double c = v * s.p[2][i] + u * s.p[3][i];
        const double ab = v * a + u * b, bc = v * b + u * c;
        r[i] = v * ab + u * bc;
    }
    return r;
}

PathPoint bezier_d1(const BezierSegment& s, double u) {
    const double v = 1 - u;
    PathPoint r(s.p[0].size());
    for (std::size_t i = 0; i < r.size(); ++i) {
        r[i] = 3 * (v * v * (s.p[1][i] - s.p[0][i]) + 2 * u * v * (s.p[2][i] - s.p[1][i]) +
                    u * u * (s.p[3][i] - s.p[2][i]));
    }
    return r;
}

PathPoint bezier_d2(const BezierSegment& s, double u) {
    const double v = 1 - u;
    PathPoint r(s.p[0].size());
    for (std::size_t i = 0; i < r.size(); ++i) {
        r[i] = 6 * (v * (s.p[2][i] - 2 * s.p[1][i] + s.p[0][i]) +
                    u * (s.p[3][i] - 2 * s.p[2][i] + s.p[1][i]));
    }
    return r;
}

void prepend_lead_in(std::vector<BezierSegment>& segments, const PathPoint& from) {
    if (segments.empty()) return;
    const PathPoint to = segments.front().p[0];
    if (from.size() != to.size()) {
        throw std::invalid_argument("lead-in: the machine has " + std::to_string(from.size()) +
                                    " axes, the path " + std::to_string(to.size()));
    }
    if (from == to) return;
    BezierSegment travel;
    travel.pen_down = false;
    travel.subpath = 0;
    for (int k = 0; k < 4; ++k) {
        travel.p[k].resize(from.size());
        for (std::size_t i = 0; i < from.size(); ++i)
            travel.p[k][i] = from[i] + (to[i] - from[i]) * k / 3.0;
    }
    travel.p[0] = from;
    travel.p[3] = to;  // exactly the path's start: consecutive segments share end points
    segments.insert(segments.begin(), travel);
}

std::vector<double> extreme_parameters(const BezierSegment& s, std::size_t axis) {
    const double p0 = s.p[0][axis], p1 = s.p[1][axis], p2 = s.p[2][axis], p3 = s.p[3][axis];
    // derivative / 3 = A u^2 + B u + C
    const double A = -p0 + 3 * p1 - 3 * p2 + p3, B = 2 * (p0 - 2 * p1 + p2), C = p1 - p0;
    std::vector<double> us{0.0, 1.0};
    const auto keep = [&us](double u) {
        if (u > 0 && u < 1) us.push_back(u);
    };
    if (std::fabs(A) > 1e-15) {
        const double disc = B * B - 4 * A * C;
        if (disc >= 0) {
            keep((-B + std::sqrt(disc)) / (2 * A));
            keep((-B - std::sqrt(disc)) / (2 * A));
        }
    } else if (std::fabs(B) > 1e-15) {
        keep(-C / B);
    }
    return us;
}

}  // namespace pathstream::host
