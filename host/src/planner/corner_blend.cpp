// Corner blending: the vertex between two straight segments of one run that turn by less than
// the stop angle becomes a short curve that stays within a fraction of the chord tolerance of
// it (or within the subpath's own smaller blend tolerance, G64 P; never in G61 or G61.1), so
// that the motion crosses the corner at the curvature's speed instead of the speed at which
// every axis can jump its velocity within one tick (docs/planner.md §3, §8).
#include "corner_blend.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>

#include "cubic.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {
namespace {

/// The unit direction and length of a straight segment (control points on the chord at thirds,
/// as polylines and G-code lines are made), or false when it is not straight.
bool straight(const BezierSegment& s, Vec& direction, double& length) {
    const Cubic c = to_cubic(s);
    const Vec chord = sub(c.p[3], c.p[0]);
    length = norm(chord);
    if (!(length > 1e-9)) return false;
    for (int k = 1; k <= 2; ++k) {
        const Vec expected = scaled(chord, k / 3.0);
        if (norm(sub(sub(c.p[static_cast<std::size_t>(k)], c.p[0]), expected)) >
            1e-9 * (1 + length))
            return false;
    }
    direction = scaled(chord, 1 / length);
    return true;
}

Vec add(const Vec& a, const Vec& b) {
    Vec r{};
    for (std::size_t i = 0; i < kAxesMax; ++i) r[i] = a[i] + b[i];
    return r;
}

PathPoint to_point(const Vec& v, std::size_t axes) {
    return PathPoint(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(axes));
}

Vec to_vec(const PathPoint& p) {
    Vec v{};
    for (std::size_t i = 0; i < p.size() && i < kAxesMax; ++i) v[i] = p[i];
    return v;
}

/// A straight segment from a to b, control points at thirds; the end points are the given
/// values exactly (joints stay shared).
void make_straight(BezierSegment& s, const PathPoint& a, const PathPoint& b) {
    const Vec va = to_vec(a), vb = to_vec(b);
    const Vec d = sub(vb, va);
    s.p[0] = a;
    s.p[1] = to_point(add(va, scaled(d, 1.0 / 3)), a.size());
    s.p[2] = to_point(add(va, scaled(d, 2.0 / 3)), a.size());
    s.p[3] = b;
}

}  // namespace

CornerBlender::CornerBlender(SegmentSource& inner, double deviation, double stop_angle)
    : inner_(inner), deviation_(deviation), stop_angle_(stop_angle) {}

bool CornerBlender::rewind() {
    ready_.clear();
    held_.reset();
    return inner_.rewind();
}

bool CornerBlender::next(BezierSegment& out) {
    while (ready_.empty()) {
        if (!held_) {
            BezierSegment s;
            if (!inner_.next(s)) return false;
            held_ = std::move(s);
            held_original_length_ = -1;
        }
        BezierSegment b;
        if (!inner_.next(b)) {
            ready_.push_back(std::move(*held_));
            held_.reset();
            break;
        }
        blend(b);
    }
    if (ready_.empty()) return false;
    out = std::move(ready_.front());
    ready_.pop_front();
    return true;
}

void CornerBlender::blend(BezierSegment& b) {
    BezierSegment& a = *held_;
    Vec ta{}, tb{};
    double la = 0, lb = 0;
    // A subpath in exact path or exact stop mode (G61, G61.1) keeps its vertices.
    const bool same_run = a.pen_down == b.pen_down && a.subpath == b.subpath && !b.pause_before &&
                          b.dwell_before == 0 && !b.stop_before && b.blend_tolerance != 0;
    if (same_run && a.p[0].size() == b.p[0].size() && a.p[0].size() <= kAxesMax &&
        straight(a, ta, la) && straight(b, tb, lb)) {
        if (held_original_length_ < 0) held_original_length_ = la;
        const double turn = std::acos(std::clamp(dot(ta, tb), -1.0, 1.0));
        if (turn > 1e-6 && turn <= stop_angle_) {
            // A quadratic Bezier from V - d ta over V to V + d tb (as a cubic) passes
            // d sin(turn / 2) / 2 from the vertex V; each leg takes at most half a segment
            // (the first one what its earlier blend left of it).
            const double half = std::sin(0.5 * turn);
            const double deviation =
                b.blend_tolerance > 0 ? std::min(deviation_, b.blend_tolerance) : deviation_;
            double d = 2 * deviation / half;
            d = std::min({d, 0.5 * held_original_length_, la, 0.5 * lb});
            if (d > 1e-6) {
                const std::size_t axes = a.p[0].size();
                const Vec v = to_vec(a.p[3]);
                const PathPoint start = to_point(sub(v, scaled(ta, d)), axes);
                const PathPoint end = to_point(add(v, scaled(tb, d)), axes);
                BezierSegment corner = a;
                corner.pause_before = false;
                corner.dwell_before = 0;
                corner.stop_before = false;
                corner.p[0] = start;
                // The quadratic's middle control point V raised to a cubic: P + 2/3 (V - P).
                corner.p[1] =
                    to_point(add(scaled(to_vec(start), 1.0 / 3), scaled(v, 2.0 / 3)), axes);
                corner.p[2] = to_point(add(scaled(to_vec(end), 1.0 / 3), scaled(v, 2.0 / 3)), axes);
                corner.p[3] = end;
                make_straight(a, a.p[0], start);
                make_straight(b, end, b.p[3]);
                ready_.push_back(std::move(a));
                ready_.push_back(std::move(corner));
                held_ = std::move(b);
                held_original_length_ = lb;
                return;
            }
        }
    }
    ready_.push_back(std::move(a));
    held_ = std::move(b);
    held_original_length_ = -1;
}

}  // namespace pathstream::host::planner_detail
