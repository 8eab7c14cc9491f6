// Path -> cubic Bezier segments in millimetres (the planner's input), and Bezier evaluation.
#include "pathstream/host/geometry.hpp"

#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "pathstream/host/segment_source.hpp"

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

/// Segment k of a subpath of m points as its basis makes it, before the joints are shared.
Controls raw_segment(const Subpath& sp, std::size_t k) {
    const PointList& pts = sp.points;
    const std::size_t m = pts.size();
    switch (sp.basis) {
        case PathBasis::kBSpline:
        case PathBasis::kCatmullRom: {
            // Open ends get phantom points 2 P0 - P1 and 2 Pm - Pm-1 (as core_spans.cpp makes
            // them); closed subpaths are periodic.
            const auto convert = [&](const Window& w) {
                return sp.basis == PathBasis::kBSpline ? bspline_to_bezier(w)
                                                       : catmull_rom_to_bezier(w);
            };
            if (sp.closed)
                return convert({pts[(k + m - 1) % m], pts[k], pts[(k + 1) % m], pts[(k + 2) % m]});
            PathPoint before, after;
            if (k == 0) before = reflect(pts[0], pts[1]);
            if (k + 3 >= m + 1) after = reflect(pts[m - 1], pts[m - 2]);
            // The extended list: before, pts[0], ..., pts[m - 1], after (m + 2 points).
            const auto ext = [&](std::size_t i) {
                return i == 0 ? PointRef(before) : i == m + 1 ? PointRef(after) : pts[i - 1];
            };
            return convert({ext(k), ext(k + 1), ext(k + 2), ext(k + 3)});
        }
        case PathBasis::kBezier:
            return {pts[3 * k], pts[3 * k + 1], pts[3 * k + 2], pts[(3 * k + 3) % m]};
        case PathBasis::kPolyline:
            break;
    }
    return straight(pts[k], pts[(k + 1) % m]);
}

}  // namespace

PathSegmentSource::PathSegmentSource(const Path& path, std::optional<PathPoint> lead_in_from)
    : path_(path), lead_in_from_(std::move(lead_in_from)) {}

bool PathSegmentSource::rewind() {
    lead_in_done_ = false;
    s_ = k_ = count_ = 0;
    in_subpath_ = any_ = false;
    held_.reset();
    next_stop_ = 0;
    return true;
}

std::size_t PathSegmentSource::size_hint() const {
    if (!sized_) {
        for (std::size_t s = 0; s < path_.subpaths.size(); ++s) {
            const Subpath& sp = path_.subpaths[s];
            const std::size_t m = sp.points.size();
            std::size_t n = 0;
            if (sp.basis == PathBasis::kBezier)
                n = sp.closed ? m / 3 : (m > 0 ? (m - 1) / 3 : 0);
            else
                n = sp.closed ? m : (m > 0 ? m - 1 : 0);
            size_ += n + (s > 0 ? 1 : 0);
        }
        sized_ = true;
    }
    return size_;
}

std::size_t PathSegmentSource::begin_subpath() {
    const Subpath& sp = path_.subpaths[s_];
    const std::size_t m = sp.points.size();
    if (m > 0 && sp.points.axes() != path_.axes) {  // a list's points have one size
        throw std::invalid_argument("subpath " + std::to_string(s_) + ": a point has " +
                                    std::to_string(sp.points.axes()) + " coordinates, expected " +
                                    std::to_string(path_.axes));
    }
    const auto too_few = [&](const char* need) {
        throw std::invalid_argument("subpath " + std::to_string(s_) + ": " + basis_name(sp.basis) +
                                    " needs " + need + " points, got " + std::to_string(m));
    };
    if (sp.basis == PathBasis::kBezier) {
        if (sp.closed ? (m < 3 || m % 3 != 0) : (m < 4 || m % 3 != 1))
            too_few(sp.closed ? "3k" : "3k + 1");
        return sp.closed ? m / 3 : (m - 1) / 3;
    }
    if (m < (sp.closed ? 3u : 2u)) too_few(sp.closed ? "at least 3" : "at least 2");
    return sp.closed ? m : m - 1;
}

void PathSegmentSource::make_segment(BezierSegment& seg) {
    const Subpath& sp = path_.subpaths[s_];
    const bool spline = sp.basis == PathBasis::kBSpline || sp.basis == PathBasis::kCatmullRom;
    Controls c = raw_segment(sp, k_);
    // Joints shared exactly (each P0 a copy of the previous P3, not merely equal to rounding),
    // the clamped open ends exactly the end points, a closed subpath ending where it starts.
    if (k_ == 0 && spline && !sp.closed) c[0] = sp.points.front().vector();
    if (k_ > 0) c[0] = previous_end_;
    if (k_ + 1 == count_) {
        if (spline && !sp.closed) c[3] = sp.points.back().vector();
        if (sp.closed) c[3] = k_ == 0 ? c[0] : first_start_;
    }
    if (k_ == 0) first_start_ = c[0];
    previous_end_ = c[3];
    const bool first = k_ == 0;
    seg = BezierSegment{};
    seg.p = std::move(c);
    seg.pen_down = !sp.travel;
    seg.subpath = s_;
    seg.feed = sp.feed;
    seg.blend_tolerance = sp.corner_mode != CornerMode::kBlend ? 0.0
                          : sp.blend_tolerance > 0             ? sp.blend_tolerance
                                                               : -1.0;
    seg.pause_before = first && sp.pause_before;
    seg.dwell_before = first ? sp.dwell_before : 0;
    seg.dwell_pen_down = first && sp.dwell_pen_down;
    seg.outputs = sp.outputs;
    seg.pause_outputs = first ? sp.pause_outputs : sp.outputs;
    const bool stops = sp.corner_mode == CornerMode::kExactStop;
    while (stops && next_stop_ < sp.stops.size() && sp.stops[next_stop_] < k_) ++next_stop_;
    seg.stop_before = stops && !first && next_stop_ < sp.stops.size() && sp.stops[next_stop_] == k_;
    seg.segment = static_cast<std::uint32_t>(k_);
    ++k_;
}

bool PathSegmentSource::next(BezierSegment& out) {
    if (held_) {
        out = std::move(*held_);
        held_.reset();
        last_end_ = out.p[3];
        return true;
    }
    while (s_ < path_.subpaths.size()) {
        if (!in_subpath_) {
            count_ = begin_subpath();
            k_ = 0;
            next_stop_ = 0;
            in_subpath_ = true;
        }
        if (k_ >= count_) {
            in_subpath_ = false;
            ++s_;
            continue;
        }
        BezierSegment seg;
        make_segment(seg);
        if (k_ == 1 && (any_ || (lead_in_from_ && !lead_in_done_))) {
            // A straight pen-up move to this start first: from the last end point, or (before
            // anything) from where the machine rests.
            const PathPoint from = any_ ? last_end_ : *lead_in_from_;
            lead_in_done_ = true;
            if (!any_ && from.size() != seg.p[0].size()) {
                throw std::invalid_argument("lead-in: the machine has " +
                                            std::to_string(from.size()) + " axes, the path " +
                                            std::to_string(seg.p[0].size()));
            }
            if (any_ || from != seg.p[0]) {
                out = BezierSegment{};
                if (any_) {
                    out.p = straight(from, seg.p[0]);
                } else {  // as prepend_lead_in makes it
                    for (int k = 0; k < 4; ++k) {
                        out.p[k].resize(from.size());
                        for (std::size_t i = 0; i < from.size(); ++i)
                            out.p[k][i] = from[i] + (seg.p[0][i] - from[i]) * k / 3.0;
                    }
                }
                out.p[0] = from;
                out.p[3] = seg.p[0];
                out.pen_down = false;
                out.subpath = any_ ? s_ : 0;
                out.outputs = seg.outputs;
                out.pause_outputs = seg.outputs;
                if (!seg.pen_down) {
                    // Joins the travel subpath's run (the lead-in too): its pause and dwell go
                    // first.
                    out.pause_before = seg.pause_before;
                    out.dwell_before = seg.dwell_before;
                    out.dwell_pen_down = seg.dwell_pen_down;
                    out.pause_outputs = seg.pause_outputs;
                    seg.pause_before = false;
                    seg.dwell_before = 0;
                    seg.dwell_pen_down = false;
                }
                any_ = true;
                held_ = std::move(seg);
                return true;
            }
        }
        any_ = true;
        out = std::move(seg);
        last_end_ = out.p[3];
        return true;
    }
    return false;
}

void for_each_bezier_segment(const Path& path,
                             const std::function<void(const BezierSegment&)>& visit) {
    PathSegmentSource source(path);
    BezierSegment seg;
    while (source.next(seg)) visit(seg);
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
