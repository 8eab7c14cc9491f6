// G-code path control modes: G64 (blend, P the most a rounded vertex may move), G61 (exact
// path: every vertex crossed as programmed) and G61.1 (exact stop: rest at every block's end),
// from the reader's subpaths through path order to the planner's stops and blends.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/path_order.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pen_plotter_profile.hpp"

using namespace pathstream::host;
using pathstream::host::test::pen_plotter;

namespace {

Path gcode(const std::string& text) {
    return parse_gcode_path(text, "t.ngc", GcodeOptions{});
}

std::string error_of(const std::string& text) {
    try {
        gcode(text);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

/// A closed polygon of `n` G1 moves on a circle of radius r (each vertex turns by 2 pi / n),
/// pen down at Z-1, after the given mode line.
std::string polygon(const std::string& mode, int n, double r) {
    std::ostringstream g;
    g.setf(std::ios::fixed);
    g.precision(9);
    g << mode << "\nG0 X" << r << " Y0\nG1 Z-1 F4800\n";
    for (int i = 1; i <= n; ++i) {
        const double t = 2 * 3.14159265358979323846 * i / n;
        g << "G1 X" << r * std::cos(t) << " Y" << r * std::sin(t) << "\n";
    }
    return g.str();
}

struct Planned {
    PlanStats stats;
    PlanCheck check;
};

Planned plan_of(const Path& path, const MachineProfile& p) {
    const auto segments = to_bezier_segments(path);
    Planned r;
    const Plan plan = plan_path(segments, p, PlanOptions{}, &r.stats);
    r.check = check_plan(plan, segments, p);
    return r;
}

}  // namespace

TEST_CASE("G-code path control: the reader keeps each mode on the subpaths it draws",
          "[host][gcode][corners]") {
    const Path blend = gcode("G0 Z-1\nG1 X10\nG1 Y10\n");
    REQUIRE(blend.subpaths.size() == 1);
    CHECK(blend.subpaths[0].corner_mode == CornerMode::kBlend);
    CHECK(blend.subpaths[0].blend_tolerance == 0);

    const Path tolerance = gcode("G64 P0.002 Q0.01\nG0 Z-1\nG1 X10\nG1 Y10\n");
    CHECK(tolerance.subpaths[0].corner_mode == CornerMode::kBlend);
    CHECK(tolerance.subpaths[0].blend_tolerance == Approx(0.002).epsilon(1e-12));
    // P is in the program's units.
    const Path inches = gcode("G20 G64 P0.001\nG0 Z-1\nG1 X1\nG1 Y1\n");
    CHECK(inches.subpaths[0].blend_tolerance == Approx(0.0254).epsilon(1e-12));

    const Path exact = gcode("G61\nG0 Z-1\nG1 X10\nG1 Y10\n");
    CHECK(exact.subpaths[0].corner_mode == CornerMode::kExactPath);
    CHECK(exact.subpaths[0].stops.empty());

    // G61.1: a rest at every block's end, not where an arc is split into cubics (each
    // half circle below is two of them).
    const Path stops =
        gcode("G61.1\nG0 X10 Y0 Z-1\nG3 X-10 Y0 I-10 J0\nG3 X10 Y0 I10 J0\nG1 X20\nG1 X30\n");
    REQUIRE(stops.subpaths.size() == 1);
    const Subpath& s = stops.subpaths[0];
    CHECK(s.corner_mode == CornerMode::kExactStop);
    CHECK(s.basis == PathBasis::kBezier);
    REQUIRE(s.points.size() == 3 * 6 + 1);
    CHECK(s.stops == std::vector<std::uint32_t>{2, 4, 5});
    // Reversed (path order draws it the other way): the same joints, counted from the new start.
    CHECK(reversed_subpath(s).stops == std::vector<std::uint32_t>{1, 2, 4});
    // A polyline's joints are its vertices.
    const Path lines = gcode("G61.1\nG0 Z-1\nG1 X10\nG1 Y10\nG1 X0\n");
    CHECK(lines.subpaths[0].basis == PathBasis::kPolyline);
    CHECK(lines.subpaths[0].stops == std::vector<std::uint32_t>{1, 2});
}

TEST_CASE("G-code path control: a mode change starts a new subpath where the run is",
          "[host][gcode][corners]") {
    const Path p = gcode("G0 Z-1\nG1 X10\nG61\nG1 Y10\nG64 P0.01\nG1 X0\nG64 P0.01\nG1 Y0\n");
    REQUIRE(p.subpaths.size() == 3);
    CHECK(p.subpaths[0].corner_mode == CornerMode::kBlend);
    CHECK(p.subpaths[1].corner_mode == CornerMode::kExactPath);
    CHECK(p.subpaths[2].corner_mode == CornerMode::kBlend);
    CHECK(p.subpaths[2].blend_tolerance == Approx(0.01));
    CHECK(p.subpaths[2].points.size() == 3);  // the repeated G64 P0.01 changes nothing
    CHECK(p.subpaths[1].location.line == 4);
    // merge_touching joins touching ends only when the corner rule is the same.
    CHECK(merge_touching(p, 1e-6).subpaths.size() == 3);
    const Path same = gcode("G0 Z-1\nG1 X10\nF600\nG1 Y10\n");
    CHECK(merge_touching(same, 1e-6).subpaths.size() == 2);  // different feeds
    const Path blend = gcode("G0 Z-1\nG1 X10\nG0 Z1\nG0 Z-1\nG1 Y10\n");
    CHECK(merge_touching(blend, 1e-6).subpaths.size() == 1);
    const Path rests = gcode("G61.1\nG0 Z-1\nG1 X10\nG0 Z1\nG0 Z-1\nG1 Y10\n");
    CHECK(merge_touching(rests, 1e-6).subpaths.size() == 2);  // a join would lose the rest between
}

TEST_CASE("G-code path control: bad words get their place", "[host][gcode][corners]") {
    CHECK(error_of("G64 P-0.1\n") == "t.ngc:1:5: G64 blend tolerance P must not be negative");
    CHECK(error_of("G64 P0.1 Q-1\n") ==
          "t.ngc:1:10: G64 naive CAM tolerance Q must not be negative");
    CHECK(error_of("G61 P0.1\n") == "t.ngc:1:5: word P is not used by any command in this block");
    CHECK(error_of("G61.1 Q1\n") == "t.ngc:1:7: word Q is not used by any command in this block");
    CHECK(error_of("G0 Z-1\nG64 G4 P1\n") ==
          "t.ngc:2:8: word P would be used by G64 and by the block's other command: give G64 a "
          "block of its own");
    CHECK(error_of("G61 G64\n") ==
          "t.ngc:1:5: G61 and G64 are in the same modal group (one per block)");
}

TEST_CASE("G-code path control: the planner blends, crosses exactly or stops as asked",
          "[planner][corners]") {
    MachineProfile p = pen_plotter();
    p.chord_tolerance = 0.05;  // blends up to 25 um from the vertex by the planner's own rule
    const int n = 50;          // 0.126 rad at every vertex, 6.3 mm sides
    const Planned blend = plan_of(gcode(polygon("G64", n, 50)), p);
    const Planned tight = plan_of(gcode(polygon("G64 P0.002", n, 50)), p);
    const Planned exact = plan_of(gcode(polygon("G61", n, 50)), p);
    const Planned stops = plan_of(gcode(polygon("G61.1", n, 50)), p);
    for (const Planned* r : {&blend, &tight, &exact, &stops}) {
        CHECK(r->check.within_limits);
        CHECK(r->check.max_feed_fraction <= 1.0);
    }
    // One piece between the pen's stops, but n pieces when every block's end is a rest.
    CHECK(blend.stats.pieces == exact.stats.pieces);
    CHECK(stops.stats.pieces == blend.stats.pieces + n - 1);
    // The tighter the rounding, the slower the corners.
    CHECK(blend.stats.motion_ticks < tight.stats.motion_ticks);
    CHECK(tight.stats.motion_ticks < exact.stats.motion_ticks);
    CHECK(exact.stats.motion_ticks < stops.stats.motion_ticks);
    // Deviation from the polygon as programmed: the rounding (at most P, or the planner's
    // corner share of chord_tolerance) plus the planner's chord share (1 - corner_blend of the
    // tolerance) plus the LSB grid. Measured: 25.4 um blended, 5.2 um with P 2 um, 3.3 um
    // exact path, 1.3 um with a rest at every vertex.
    const double grid = 1.5 * std::sqrt(2.0) * p.mm_per_lsb;
    const double chord_share = 0.5 * p.chord_tolerance;
    CHECK(tight.check.max_deviation <= 0.002 + chord_share + grid);
    CHECK(exact.check.max_deviation <= chord_share + grid);
    CHECK(stops.check.max_deviation <= chord_share + grid);
    CHECK(blend.check.max_deviation <= 2 * chord_share + grid);
    CHECK(blend.check.max_deviation > 0.02);  // the planner's own rounding, far above P
    CHECK(tight.check.max_deviation < 0.5 * blend.check.max_deviation);
}
