// The G-code reader on a machine (axes X Y Z, --gcode-pen machine): moves in the program's
// order with rapids as routed travel, planes and helices, canned cycles, offsets and the tool
// table, polar coordinates, checksums, feed modes; each against hand-computed moves.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/host/gcode_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

constexpr double kPi = std::numbers::pi;

GcodeOptions router(const std::string& axes = "XYZ") {
    GcodeOptions o;
    o.axes = axes;
    o.pen = PenControl::kMachine;
    o.rapid_feed = 150;
    return o;
}

Path gcode(const std::string& text, const GcodeOptions& options = router()) {
    return parse_gcode_path(text, "t.ngc", options);
}

std::string error_of(const std::string& text, const GcodeOptions& options = router()) {
    try {
        gcode(text, options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

/// A move's end point, and whether it was a rapid (travel) or a feed move.
struct Waypoint {
    bool travel;
    std::vector<double> at;
};

/// The end point of every curve segment, in order.
std::vector<Waypoint> waypoints(const Path& path) {
    std::vector<Waypoint> out;
    for (const Subpath& s : path.subpaths) {
        const std::size_t step = s.basis == PathBasis::kBezier ? 3 : 1;
        for (std::size_t i = step; i < s.points.size(); i += step)
            out.push_back({s.travel, s.points[i].vector()});
    }
    return out;
}

void check_waypoints(const Path& path, const std::vector<Waypoint>& expected) {
    const std::vector<Waypoint> got = waypoints(path);
    REQUIRE(got.size() == expected.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
        INFO("waypoint " << i);
        CHECK(got[i].travel == expected[i].travel);
        REQUIRE(got[i].at.size() == expected[i].at.size());
        for (std::size_t a = 0; a < got[i].at.size(); ++a)
            CHECK(got[i].at[a] == Approx(expected[i].at[a]).margin(1e-9));
    }
}

std::vector<double> bezier(const Subpath& s, std::size_t piece, double t) {
    const double u = 1 - t;
    std::vector<double> p(s.points.axes());
    for (std::size_t a = 0; a < p.size(); ++a) {
        p[a] = u * u * u * s.points[3 * piece][a] + 3 * u * u * t * s.points[3 * piece + 1][a] +
               3 * u * t * t * s.points[3 * piece + 2][a] + t * t * t * s.points[3 * piece + 3][a];
    }
    return p;
}

constexpr bool T = true, D = false;

}  // namespace

TEST_CASE("G-code machine: Z is an axis and rapids keep their waypoints", "[gcode][machine]") {
    const Path p = gcode("G21 G90\nG0 Z5\nG0 X10 Y10\nG1 Z-1 F600\nG1 X20\nG0 Z5\nM2\n");
    CHECK(p.axes == 3);
    check_waypoints(
        p,
        {{T, {0, 0, 5}}, {T, {10, 10, 5}}, {D, {10, 10, -1}}, {D, {20, 10, -1}}, {T, {20, 10, 5}}});
    REQUIRE(p.subpaths.size() == 3);
    CHECK(p.subpaths[0].feed == 150);  // rapids: GcodeOptions::rapid_feed
    CHECK(p.subpaths[1].feed == 10);   // F600 mm/min
    // A plotter reads the same program with Z as its pen: only the feed move at Z-1 draws.
    const Path plot = gcode("G21 G90\nG0 Z5\nG0 X10 Y10\nG1 Z-1 F600\nG1 X20\nG0 Z5\nM2\n", {});
    CHECK(plot.axes == 2);
    check_waypoints(plot, {{D, {20, 10}}});
}

TEST_CASE("G-code machine: helical arcs stay on the helix", "[gcode][machine]") {
    // Three turns of radius 10 about the origin, falling 6 mm, then a flat turn.
    const Path p = gcode("G0 X10 Y0 Z0\nG3 X10 Y0 I-10 J0 Z-6 P3 F600\n");
    REQUIRE(p.subpaths.size() == 2);
    const Subpath& helix = p.subpaths[1];
    REQUIRE(helix.basis == PathBasis::kBezier);
    const std::size_t pieces = (helix.points.size() - 1) / 3;
    CHECK(pieces >= 12);
    CHECK(helix.points[helix.points.size() - 1].vector() == std::vector<double>{10, 0, -6});
    double turned = 0, last_angle = 0, worst = 0;
    for (std::size_t k = 0; k < pieces; ++k) {
        for (int j = 0; j <= 16; ++j) {
            const std::vector<double> q = bezier(helix, k, j / 16.0);
            const double angle = std::atan2(q[1], q[0]);
            turned += std::remainder(angle - last_angle, 2 * kPi);
            last_angle = angle;
            const double z = -6 * turned / (6 * kPi);
            worst = std::max(worst, std::hypot(std::hypot(q[0], q[1]) - 10, q[2] - z));
        }
    }
    CHECK(turned == Approx(6 * kPi));
    CHECK(worst <= 0.01);  // the arc tolerance
}

TEST_CASE("G-code machine: G18 and G19 arcs turn as LinuxCNC's", "[gcode][machine]") {
    // G18: the plane is Z X (K I offsets); G2 is clockwise seen from +Y, so from X10 Z0 about
    // the origin to X0 Z10 it is the quarter through X7.07 Z7.07.
    const Path zx = gcode("G0 X10 Y0 Z0\nG18 G2 X0 Z10 I-10 K0 F600\n");
    const std::vector<double> mid = bezier(zx.subpaths[1], 0, 0.5);
    CHECK(mid[0] == Approx(10 * std::sqrt(0.5)).margin(0.01));
    CHECK(mid[2] == Approx(10 * std::sqrt(0.5)).margin(0.01));
    CHECK(mid[1] == 0);
    // G19: the plane is Y Z (J K); G3 from Y10 Z0 about the origin to Y0 Z10 is the quarter.
    const Path yz = gcode("G0 X0 Y10 Z0\nG19 G3 Y0 Z10 J-10 K0 F600\n");
    const std::vector<double> mid2 = bezier(yz.subpaths[1], 0, 0.5);
    CHECK(mid2[1] == Approx(10 * std::sqrt(0.5)).margin(0.01));
    CHECK(mid2[2] == Approx(10 * std::sqrt(0.5)).margin(0.01));
    CHECK(error_of("G0 X10\nG18 G2 X0 Z10 J1 K0 F600") ==
          "t.ngc:2:15: J is no center offset of a G18 arc (it takes K and I)");
}

TEST_CASE("G-code machine: G81 with G99 and L repeats in G91", "[gcode][machine][cycle]") {
    // R = 10 - 8 = 2 and the bottom 2 - 5 = -3 (G91: R from the initial Z, Z from R).
    const Path p = gcode("G0 X0 Y0 Z10\nG91 G99 G81 X10 Y0 Z-5 R-8 L3 F600\n");
    check_waypoints(p, {{T, {0, 0, 10}},
                        {T, {10, 0, 10}},
                        {T, {10, 0, 2}},
                        {D, {10, 0, -3}},
                        {T, {10, 0, 2}},
                        {T, {20, 0, 2}},
                        {D, {20, 0, -3}},
                        {T, {20, 0, 2}},
                        {T, {30, 0, 2}},
                        {D, {30, 0, -3}},
                        {T, {30, 0, 2}}});
}

TEST_CASE("G-code machine: G83 pecks and G98 returns to the initial Z", "[gcode][machine][cycle]") {
    const Path p = gcode("G0 X0 Y0 Z10\nG98 G83 X5 Y5 Z-5 R2 Q3 F600\nG80\n");
    // Pecks of 3 from R2: -1, -4, -5; between them up to R and back down to 0.254 mm above.
    check_waypoints(p, {{T, {0, 0, 10}},
                        {T, {5, 5, 10}},
                        {T, {5, 5, 2}},
                        {D, {5, 5, -1}},
                        {T, {5, 5, 2}},
                        {T, {5, 5, -0.746}},
                        {D, {5, 5, -4}},
                        {T, {5, 5, 2}},
                        {T, {5, 5, -3.746}},
                        {D, {5, 5, -5}},
                        {T, {5, 5, 10}}});
    // G73 breaks the chip with a 0.254 mm rapid up; G82 dwells at the bottom.
    const Path chip = gcode("G0 X0 Y0 Z2\nG99 G73 X0 Y0 Z-5 R2 Q3 F600\n");
    check_waypoints(chip, {{T, {0, 0, 2}},
                           {D, {0, 0, -1}},
                           {T, {0, 0, -0.746}},
                           {D, {0, 0, -4}},
                           {T, {0, 0, -3.746}},
                           {D, {0, 0, -5}},
                           {T, {0, 0, 2}}});
    const Path dwell = gcode("G0 Z5\nG82 X1 Y1 Z-1 R1 P0.5 F600\n");
    // The cycle runs in exact path mode: its moves are subpaths of their own (G64 outside).
    REQUIRE(dwell.subpaths.size() == 4);
    CHECK(dwell.subpaths[3].travel);
    CHECK(dwell.subpaths[3].dwell_before == 0.5);
    CHECK(dwell.subpaths[3].corner_mode == CornerMode::kExactPath);
    // Sticky R and Z: the next block drills the next hole the same way.
    check_waypoints(gcode("G0 Z5\nG81 X1 Y1 Z-1 R1 F600\nX2\n"), {{T, {0, 0, 5}},
                                                                  {T, {1, 1, 5}},
                                                                  {T, {1, 1, 1}},
                                                                  {D, {1, 1, -1}},
                                                                  {T, {1, 1, 5}},
                                                                  {T, {2, 1, 5}},
                                                                  {T, {2, 1, 1}},
                                                                  {D, {2, 1, -1}},
                                                                  {T, {2, 1, 5}}});
    CHECK(error_of("G0 Z5\nG81 X1 Y1 Z2 R1 F600") ==
          "t.ngc:2:11: G81: the bottom Z is above the retract plane R");
    CHECK(error_of("G0 Z5\nG83 X1 Y1 Z-2 R1 F600") == "t.ngc:2:1: G83 needs Q (the peck depth)");
    CHECK(error_of("G0 Z5\nG81 X1 Y1 Z-2 F600") == "t.ngc:2:1: G81 needs R (the retract plane)");
    CHECK(error_of("G84 X1 Y1 Z-2 R1") ==
          "t.ngc:1:1: G84 (tapping) needs a spindle whose turning the axes follow; this "
          "machine's spindle is an output");
}

TEST_CASE("G-code machine: coordinate systems, G92 and tool length offsets", "[gcode][machine]") {
    const std::string table_file = "gcode_machine_tools.tbl";
    std::ofstream(table_file) << "; tools\nT1 P1 Z25 D6 ; end mill\nT2 P2 Z-1.5\n";
    GcodeOptions o = router();
    o.tool_table = table_file;
    const Path p = gcode(
        "G10 L2 P1 X100 Y50 Z-20\n"
        "G54 G0 X0 Y0 Z0\n"              // (100, 50, -20)
        "G10 L20 P2 X0 Y0 Z0\n"          // G55's origin is here
        "G55 G0 X1\n"                    // (101, 50, -20)
        "G92 X0\n"                       // this point is X0 now
        "G0 X5\n"                        // (106, 50, -20)
        "G92.1 G0 X5\n"                  // (105, 50, -20)
        "G43 H1 G0 Z0\n"                 // (105, 50, 5)
        "G43.1 Z3\nG0 Z0\n"              // (105, 50, -17)
        "G49 G0 Z0\n"                    // (105, 50, -20)
        "G91 G10 L2 P2 X1\nG90 G0 X0\n"  // G91 changes nothing: G55's X is 1
        "G1 X1 F60\n",
        o);
    check_waypoints(p, {{T, {100, 50, -20}},
                        {T, {101, 50, -20}},
                        {T, {106, 50, -20}},
                        {T, {105, 50, -20}},
                        {T, {105, 50, 5}},
                        {T, {105, 50, -17}},
                        {T, {105, 50, -20}},
                        {T, {1, 50, -20}},
                        {D, {2, 50, -20}}});
    CHECK(error_of("G43 H9 G0 Z0\nG1 X1 F60", o) ==
          "t.ngc:1:5: G43 H9: tool 9 is not in the tool table gcode_machine_tools.tbl");
    CHECK(error_of("G43 H1\nG1 X1 F60") ==
          "t.ngc:1:5: G43 H1: no tool table (give one with --tool-table)");
    CHECK(error_of("G10 L1 P1 Z3\n") ==
          "t.ngc:1:5: G10 L1 edits the tool table: edit the tool table file instead");
    CHECK(error_of("G10 L2 P10 X1\n") ==
          "t.ngc:1:8: G10 L2 needs P from 0 (the current system) to 9 (G59.3)");
}

TEST_CASE("G-code machine: the tool table's errors name the line", "[gcode][machine]") {
    auto table_error = [](const std::string& text) {
        std::ofstream("gcode_machine_bad.tbl") << text;
        GcodeOptions o = router();
        o.tool_table = "gcode_machine_bad.tbl";
        try {
            gcode("G1 X1 F60", o);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(table_error("T1 P1 Z1\nP2 Z3\n") ==
          "gcode_machine_bad.tbl:2:1: tool line without T (the tool number)");
    CHECK(table_error("T1 Z1\nT1 Z2\n") == "gcode_machine_bad.tbl:2:1: tool T1 is given twice");
    CHECK(table_error("T1 E2\n") ==
          "gcode_machine_bad.tbl:1:4: unknown tool table word E (T P X Y Z A B C U V W D I J Q)");
    CHECK(table_error("T1.5\n") == "gcode_machine_bad.tbl:1:1: T must be a whole number >= 0");
    CHECK(table_error("T1 Z\n") == "gcode_machine_bad.tbl:1:5: missing number after Z");
}

TEST_CASE("G-code machine: polar coordinates", "[gcode][machine]") {
    // G90: about the origin; G91: ^ and @ add to the current point's angle and distance.
    check_waypoints(gcode("G1 @10 ^90 F600\nG91 ^90\nG90 @5\nG91 @2 ^-90\n"),
                    {{D, {0, 10, 0}}, {D, {-10, 0, 0}}, {D, {-5, 0, 0}}, {D, {0, 7, 0}}});
}

TEST_CASE("G-code machine: checksums as senders write them", "[gcode][machine]") {
    const std::string line = "N12 G1 X5 F600";
    unsigned sum = 0;
    for (const char c : line) sum ^= static_cast<unsigned char>(c);
    check_waypoints(gcode(line + "*" + std::to_string(sum) + "\n"), {{D, {5, 0, 0}}});
    CHECK(error_of(line + "*" + std::to_string(sum ^ 1u)) ==
          "t.ngc:1:15: checksum *" + std::to_string(sum ^ 1u) + " does not match the line (*" +
              std::to_string(sum) + ")");
    CHECK(error_of("G1 X5 F600*") == "t.ngc:1:11: a checksum '*' needs a number 0..255");
}

TEST_CASE("G-code machine: feed modes and rotary axes", "[gcode][machine]") {
    // G93: 60 mm in 1/2 minute is 2 mm/s.
    CHECK(gcode("G93 G1 X60 F2\n").subpaths[0].feed == Approx(2));
    CHECK(error_of("G93 G1 X60 F2\nX70\n") ==
          "t.ngc:2:1: G93 (inverse time) needs F on every feed move");
    // F is along X Y Z; the path's feed is along every axis (A in degrees).
    const Path a = gcode("G1 X30 A40 F600\nG1 A90\n", router("XYZA"));
    REQUIRE(a.subpaths.size() == 2);
    CHECK(a.subpaths[0].feed == Approx(10.0 * 50 / 30));
    CHECK(a.subpaths[1].feed == Approx(10));  // A alone: F600 degrees per minute
    CHECK(error_of("G1 X10\n") == "t.ngc:1:1: feed move with no feed rate (give F first)");
    CHECK(error_of("G1 X10 B1 F60\n") ==
          "t.ngc:1:8: axis B is not one of this machine's axes (XYZ)");
}

TEST_CASE("G-code machine: M6 pauses, and pen modes that cannot be", "[gcode][machine]") {
    const Path p = gcode("G0 Z5\nG1 X1 F60\nT2 M6\nG1 X2\n");
    REQUIRE(p.subpaths.size() == 3);
    CHECK(p.subpaths[2].pause_before);
    GcodeOptions z = router();
    z.pen = PenControl::kZ;
    CHECK_THROWS_AS(gcode("G1 X1 F60\n", z), std::invalid_argument);
    GcodeOptions bad = router("XZ");
    CHECK_THROWS_AS(gcode("G1 X1 F60\n", bad), std::invalid_argument);
}

TEST_CASE("G-code machine: a series of cycles as LinuxCNC runs it", "[gcode][machine][cycle]") {
    // The initial level stays for the series: G98 after G99 goes back to Z10, not to R.
    check_waypoints(gcode("G0 Z10\nG99 G81 X1 Y0 Z-1 R2 F600\nG98 X2\n"), {{T, {0, 0, 10}},
                                                                           {T, {1, 0, 10}},
                                                                           {T, {1, 0, 2}},
                                                                           {D, {1, 0, -1}},
                                                                           {T, {1, 0, 2}},
                                                                           {T, {2, 0, 2}},
                                                                           {D, {2, 0, -1}},
                                                                           {T, {2, 0, 10}}});
    // G89 dwells and feeds straight out to the clearance level.
    const Path g89 = gcode("G0 Z10\nG98 G89 X1 Y0 Z-1 R2 P1 F600\n");
    const std::vector<Waypoint> w = waypoints(g89);
    REQUIRE(w.size() == 5);
    CHECK_FALSE(w[4].travel);
    CHECK(w[4].at == std::vector<double>{1, 0, 10});
    CHECK(error_of("G0 Z5\nG86 X1 Y1 Z-1 R1 F600") ==
          "t.ngc:2:1: G86 needs P (the dwell at the bottom, seconds)");
    // A new cycle mode needs its words again.
    CHECK(error_of("G0 Z5\nG81 X1 Y1 Z-1 R1 F600\nG82 X2 P1") ==
          "t.ngc:3:1: G82 needs R (the retract plane)");
    CHECK(error_of("G0 Z5\nG81 X1 Y1 Z-1 R1 L0 F600") ==
          "t.ngc:2:18: L (repeats) must be a whole number from 1 to 100000");
    CHECK(error_of("G0 Z5\nG81 X1 Y1 Z-1 R1 A3 F600", router("XYZA")) ==
          "t.ngc:2:18: axis word A in a canned cycle (G81)");
    CHECK(error_of("G0 Z5\nG93 G81 X1 Y1 Z-1 R1 F6") ==
          "t.ngc:2:5: G81 with inverse time feed (G93): give G94");
}

TEST_CASE("G-code machine: the loaded tool, G43.1 and units", "[gcode][machine]") {
    const std::string table_file = "gcode_machine_tools2.tbl";
    std::ofstream(table_file) << "T3 P3 Z10 D6 ; ball\n";
    GcodeOptions o = router();
    o.tool_table = table_file;
    // G43 without H: the tool M6 loaded; G43.1 X replaces X's offset and keeps Z's.
    check_waypoints(gcode("T3 M6\nG43\nG0 Z0\nG43.1 X1\nG0 X0\nG1 X1 F60\n", o),
                    {{T, {0, 0, 10}}, {T, {1, 0, 10}}, {D, {2, 0, 10}}});
    // No tool loaded is tool 0, whose offsets are 0 (LinuxCNC).
    check_waypoints(gcode("G43\nG1 X1 F60\n", o), {{D, {1, 0, 0}}});
    // M61 Q sets the tool in the spindle without a change: G43 takes its offsets.
    check_waypoints(gcode("M61 Q3\nG43\nG1 X1 Z0 F60\n", o), {{D, {1, 0, 10}}});
    // G20: F is inches per minute along X, degrees per minute along A alone.
    const Path inch = gcode("G20 G1 X1 F60\nG1 A90\n", router("XYZA"));
    CHECK(inch.subpaths[0].feed == Approx(25.4));
    CHECK(inch.subpaths[1].feed == Approx(1));
    // G93 -> G94 needs a new F.
    CHECK(error_of("G93 G1 X1 F2\nG94 G1 X2\n") ==
          "t.ngc:2:5: feed move with no feed rate (give F first)");
    CHECK(error_of("G1 @5 F60\n") ==
          "t.ngc:1:4: polar coordinates at the origin need ^ (the angle)");
}

TEST_CASE("G-code: subroutine files, labels from parameters, LinuxCNC's parameter forms",
          "[gcode][oword]") {
    std::filesystem::create_directories("gcode_subs/lib");
    std::ofstream("gcode_subs/lib/touchoff.ngc")
        << "o<touchoff> sub\nG1 X[#1] Y[#2]\no<touchoff> endsub\n";
    std::ofstream("gcode_subs/lib/bad.ngc") << "o<bad> sub\nG1 X1 Q\no<bad> endsub\n";
    std::ofstream("gcode_subs/lib/other.ngc") << "o<elsewhere> sub\no<elsewhere> endsub\n";
    GcodeOptions o = router();
    o.subroutine_path = {"gcode_subs/none", "gcode_subs/lib"};
    // The file's subroutine, then one the program defines called through a parameter, then
    // #ATAN[1]/[1] is #45 and EXISTS of a numbered parameter is 1.
    check_waypoints(gcode("G1 X0 F60\no<touchoff> call [5] [7]\n#<s>=100\no100 sub\nG1 X1 Y1\n"
                          "o100 endsub\no#<s> call\n#atan[1]/[1]=3\no1 if [EXISTS[#1]]\n"
                          "G1 X#45\no1 endif\no<touchoff> call [2] [2]\n",
                          o),
                    {{D, {5, 7, 0}}, {D, {1, 1, 0}}, {D, {3, 1, 0}}, {D, {2, 2, 0}}});
    // Errors in a subroutine file name that file.
    CHECK(error_of("G1 X0 F60\no<bad> call\n", o) ==
          "gcode_subs/lib/bad.ngc:2:7: missing number after Q");
    CHECK(error_of("o<missing> call\n", o) ==
          "t.ngc:1:1: O<missing> call: no such subroutine in this file, nor missing.ngc in the "
          "subroutine path (gcode_subs/none, gcode_subs/lib)");
    std::filesystem::copy_file("gcode_subs/lib/other.ngc", "gcode_subs/lib/misnamed.ngc",
                               std::filesystem::copy_options::overwrite_existing);
    CHECK(error_of("o<misnamed> call\n", o) ==
          "t.ngc:1:1: O<misnamed> call: gcode_subs/lib/misnamed.ngc does not define "
          "O<misnamed> sub");
    CHECK(error_of("o#<s> sub\no#<s> endsub\n", o) ==
          "t.ngc:1:1: only a call may take its label from a parameter (O#... call)");
}

TEST_CASE("G-code machine: M60 pauses and user M codes are refused", "[gcode][machine]") {
    const Path p = gcode("G1 X1 F60\nM60\nG1 X2\n");
    REQUIRE(p.subpaths.size() == 2);
    CHECK(p.subpaths[1].pause_before);
    CHECK(p.subpaths[1].pause_note == "pallet change (M60), line 2");
    CHECK(error_of("G1 X1 F60\nM101\n") ==
          "t.ngc:2:1: user M code M101: LinuxCNC runs a program of that name, this reader runs "
          "none (skip it with --ignore-code M101 if it means nothing here)");
    GcodeOptions skip = router();
    skip.ignore_codes = {"M101"};
    CHECK(gcode("G1 X1 F60\nM101 P3\nG1 X2\n", skip).subpaths.size() == 1);
}

TEST_CASE("G-code machine: cutter radius compensation in the reader", "[gcode][machine][cutter]") {
    // A 40 x 30 rectangle counterclockwise with the tool (6 mm) on its left: inside, its
    // center 3 mm in from every side; the exit move after G40 starts from the tool center.
    const Path p = gcode(
        "G0 X20 Y10\nG41.1 D6\nG1 X20 Y0 F600\nX40 Y0\nX40 Y30\nX0 Y30\nX0 Y0\nX20 Y0\nG40\n"
        "G0 X20 Y10\n");
    std::vector<std::vector<double>> corners;
    for (const Waypoint& w : waypoints(p)) {
        if (!w.travel) corners.push_back(w.at);
    }
    const std::vector<std::vector<double>> expected{{20, 3, 0}, {37, 3, 0}, {37, 27, 0},
                                                    {3, 27, 0}, {3, 3, 0},  {20, 3, 0}};
    REQUIRE(corners.size() >= expected.size());
    for (const auto& e : expected) {
        bool found = false;
        for (const auto& c : corners) {
            found = found || (std::fabs(c[0] - e[0]) < 1e-9 && std::fabs(c[1] - e[1]) < 1e-9);
        }
        INFO("corner " << e[0] << ", " << e[1]);
        CHECK(found);
    }
    // Nothing of the tool path leaves the inside by less than the radius.
    for (const Subpath& s : p.subpaths) {
        for (std::size_t i = 0; i < s.points.size(); ++i) {
            if (s.travel) continue;
            CHECK(s.points[i][0] >= 3 - 1e-9);
            CHECK(s.points[i][0] <= 37 + 1e-9);
        }
    }
    CHECK(error_of("G41.1 D6\nG41.1 D6\n") ==
          "t.ngc:2:1: cutter radius compensation is on already (give G40 first)");
    CHECK(error_of("G41.1 D6\nG1 X10 F60\nG18\n") ==
          "t.ngc:3:1: a plane change while cutter radius compensation is on (give G40 first; it "
          "began at line 1)");
    CHECK(error_of("G41 D1\n") == "t.ngc:1:1: G41/G42: no tool table (give one with --tool-table)");
    CHECK(error_of("G1 X1 D3 F60\n") ==
          "t.ngc:1:7: word D is not used by any command in this block");
}

TEST_CASE("G-code machine: a bolt circle with polar words in a cycle", "[gcode][machine][cycle]") {
    // Four holes 10 mm from the origin, 90 degrees apart: G91 turns ^ on each L repeat.
    const Path p = gcode("G0 Z5\nG90 G81 @10 ^0 Z-1 R1 F600\nG91 G81 ^90 Z-2 R-4 L3\n");
    std::vector<std::vector<double>> bottoms;
    for (const Waypoint& w : waypoints(p)) {
        if (!w.travel) bottoms.push_back(w.at);
    }
    REQUIRE(bottoms.size() == 4);
    const double expected[4][2] = {{10, 0}, {0, 10}, {-10, 0}, {0, -10}};
    for (std::size_t k = 0; k < 4; ++k) {
        CHECK(bottoms[k][0] == Approx(expected[k][0]).margin(1e-9));
        CHECK(bottoms[k][1] == Approx(expected[k][1]).margin(1e-9));
        CHECK(bottoms[k][2] == Approx(-1).margin(1e-9));
    }
    // A return under an if's label leaves the subroutine it is in, as LinuxCNC's demos do.
    check_waypoints(gcode("o<s> sub\no<t> if [1]\no<t> return\no<t> endif\nG1 X9 F60\no<s> endsub\n"
                          "o<s> call\nG1 X1 F60\n"),
                    {{D, {1, 0, 0}}});
}

TEST_CASE("G-code machine: cutter compensation in G18, as on a lathe", "[gcode][machine][cutter]") {
    // In G18 the plane is Z X and the tool's left is seen from +Y: going toward -Z at X10, a
    // tool of radius 1 on the left runs at X9.
    const Path p = gcode("G18 G0 X12 Z2\nG41.1 D2\nG1 X10 Z0 F60\nG1 Z-20\nG40\nG0 X12\n");
    std::vector<Waypoint> feeds;
    for (const Waypoint& w : waypoints(p)) {
        if (!w.travel) feeds.push_back(w);
    }
    REQUIRE_FALSE(feeds.empty());
    CHECK(feeds.back().at[0] == Approx(9).margin(1e-9));
    CHECK(feeds.back().at[2] == Approx(-20).margin(1e-9));
    CHECK(error_of("G19 G41.1 D2\n") ==
          "t.ngc:1:5: cutter radius compensation needs G17 or G18, not G19");
}

TEST_CASE("G-code machine: M70-M73 save and restore the modes", "[gcode][machine]") {
    // M70 saves G21 G90; the program switches to G20 G91, M72 brings back mm and absolute.
    check_waypoints(gcode("G21 G90 F60\nM70\nG20 G91\nG1 X1\nM72\nG1 X5\n"),
                    {{D, {25.4, 0, 0}}, {D, {5, 0, 0}}});
    // M73 in a subroutine: its mode changes end with the call.
    check_waypoints(gcode("o<s> sub\nM73\nG91\nG1 X1\no<s> endsub\nG90 F60\no<s> call\nG1 X5\n"),
                    {{D, {1, 0, 0}}, {D, {5, 0, 0}}});
    CHECK(error_of("M72\n") == "t.ngc:1:1: M72 without a state saved by M70");
    CHECK(error_of("M73\n") == "t.ngc:1:1: M73 outside a subroutine");
}
