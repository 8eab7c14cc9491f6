// Corner blending: shallow polyline vertices become curves within the chord tolerance, so the
// motion crosses them at the curve's speed; the plan still passes the exact per-tick check and
// stays within the tolerance of the polyline as given. Sharp vertices still stop.
#include <catch2/catch.hpp>
#include <cmath>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pen_plotter_profile.hpp"

using namespace pathstream::host;
using pathstream::host::test::pen_plotter;

namespace {

/// A polygon of `n` vertices on a circle of radius r: every vertex turns by 2 pi / n.
Path polygon(int n, double r) {
    Path path;
    path.axes = 2;
    Subpath s;
    s.basis = PathBasis::kPolyline;
    for (int i = 0; i <= n; ++i) {
        const double t = 2 * 3.14159265358979 * i / n;
        s.points.push_back({r * std::cos(t), r * std::sin(t)});
    }
    path.subpaths.push_back(s);
    return path;
}

}  // namespace

TEST_CASE("shallow vertices are blended within the tolerance and crossed faster",
          "[planner][blend]") {
    const MachineProfile p = pen_plotter();
    const Path path = polygon(50, 50);  // 0.126 rad at every vertex, 6.3 mm sides
    const auto segments = to_bezier_segments(path);
    PlanOptions corners;
    corners.corner_blend = 0;
    PlanStats blended_stats, corner_stats;
    const Plan blended = plan_path(segments, p, PlanOptions{}, &blended_stats);
    const Plan cornered = plan_path(segments, p, corners, &corner_stats);
    const PlanCheck check = check_plan(blended, segments, p);  // against the polygon as given
    CHECK(check.within_limits);
    CHECK(check.max_deviation <= p.chord_tolerance + 1.5 * std::sqrt(2.0) * p.mm_per_lsb);
    CHECK(check.max_feed_fraction <= 1.0);
    // Crossed at the speed of a curve of ~1.6 mm radius (sqrt(a r) ~ 69 mm/s) instead of the
    // one-tick velocity step of the corner rule (~24 mm/s).
    CHECK(blended_stats.motion_ticks < 0.85 * static_cast<double>(corner_stats.motion_ticks));
    // The blended path's own continuous optimum is what the motion is compared with.
    CHECK(static_cast<double>(blended_stats.motion_ticks) / p.tick_hz >=
          blended_stats.reference_motion_time);
}

TEST_CASE("sharp vertices still stop, a blend never crosses a pen change", "[planner][blend]") {
    const MachineProfile p = pen_plotter();
    const Path square = polygon(4, 20);
    const auto segments = to_bezier_segments(square);
    const Plan plan = plan_path(segments, p);
    const PlanCheck check = check_plan(plan, segments, p);
    CHECK(check.within_limits);
    // Each 90-degree vertex is an exact stop: a span ends there at rest.
    int stops = 0;
    for (std::size_t i = 0; i + 1 < plan.spans.size(); ++i) {
        const auto& a = plan.spans[i];
        bool at_rest = a.pen_down;
        for (std::size_t axis = 0; axis < 2; ++axis)
            at_rest =
                at_rest && a.control[axis][3] == 0 && a.control[axis][1] != a.control[axis][0];
        if (at_rest) ++stops;
    }
    CHECK(stops >= 4);
}

TEST_CASE("a profile's corner_stop_angle turns shallow vertices into stops", "[planner][blend]") {
    MachineProfile p = pen_plotter();
    const Path path = polygon(12, 20);  // 0.524 rad (30 degrees) at every vertex
    const auto segments = to_bezier_segments(path);
    PlanStats crossed_stats, stopped_stats;
    p.corner_stop_angle = 40 * 3.14159265358979 / 180;  // above the vertices' turn: blended
    const Plan crossed = plan_path(segments, p, PlanOptions{}, &crossed_stats);
    p.corner_stop_angle = 10 * 3.14159265358979 / 180;  // below it: every vertex stops
    const Plan stopped = plan_path(segments, p, PlanOptions{}, &stopped_stats);
    CHECK(check_plan(crossed, segments, p).within_limits);
    CHECK(check_plan(stopped, segments, p).within_limits);
    CHECK(crossed_stats.pieces < stopped_stats.pieces);
    CHECK(stopped_stats.pieces >= 12);  // one piece per side at least
}
