// The G-code reader's RS274NGC language: parameters, expressions, O-word control flow,
// offsets and homing, dwell and pauses, skipped codes and budgets; black-box through
// parse_gcode_path.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "pathstream/host/gcode_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

Path run(const std::string& text, const GcodeOptions& options = {}, GcodeReadInfo* info = nullptr) {
    return parse_gcode_path(text, "t.ngc", options, info);
}

std::string error_of(const std::string& text, const GcodeOptions& options = {}) {
    try {
        run(text, options);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

/// The end of the last subpath drawn.
std::pair<double, double> last_point(const Path& p) {
    const PathPoint& q = p.subpaths.back().points.back();
    return {q[0], q[1]};
}

/// X of the end of a program that draws one line from X0 to X<value> (value: an expression).
double x_of(const std::string& value) {
    const Path p = run("G1 Z-1\nG1 Y1 X" + value + "\n");
    return last_point(p).first;
}

}  // namespace

TEST_CASE("G-code: expressions and precedence", "[gcode]") {
    CHECK(x_of("[1+2]") == Approx(3));
    CHECK(x_of("[1+2*3]") == Approx(7));
    CHECK(x_of("[2**3**2]") == Approx(64));  // left to right, as LinuxCNC
    CHECK(x_of("[2*3**2]") == Approx(18));
    CHECK(x_of("[10-4-3]") == Approx(3));
    CHECK(x_of("[7 MOD 3]") == Approx(1));
    CHECK(x_of("[-7 MOD 3]") == Approx(2));
    CHECK(x_of("[1+2 EQ 3]") == Approx(1));  // relational binds looser than +
    CHECK(x_of("[1 LT 2 AND 3 GT 4]") == Approx(0));
    CHECK(x_of("[1 LT 2 OR 3 GT 4]") == Approx(1));
    CHECK(x_of("[1 XOR 1]") == Approx(0));
    CHECK(x_of("[[2 GE 2] + [2 LE 1] + [2 NE 3]]") == Approx(2));
    CHECK(x_of("-[2+3]") == Approx(-5));
    CHECK(x_of("[SIN[30]*10]") == Approx(5));
    CHECK(x_of("[COS[60]+TAN[45]]") == Approx(1.5));
    CHECK(x_of("ATAN[1]/[1]") == Approx(45));
    CHECK(x_of("[ASIN[1]+ACOS[0]]") == Approx(180));
    CHECK(x_of("[SQRT[16]+ABS[-2]]") == Approx(6));
    CHECK(x_of("[FIX[2.7]+FUP[2.1]+ROUND[2.5]]") == Approx(8));
    CHECK(x_of("[LN[EXP[2]]]") == Approx(2));
    CHECK(x_of("[EXISTS[#<nope>]]") == Approx(0));
}

TEST_CASE("G-code: expression errors", "[gcode]") {
    CHECK(error_of("G1 X[1/0]") == "t.ngc:1:7: division by zero");
    CHECK(error_of("G1 X[SQRT[-1]]") == "t.ngc:1:6: SQRT of -1: negative");
    CHECK(error_of("G1 X[1+2") == "t.ngc:1:5: unclosed '['");
    CHECK(error_of("G1 X[1 2]") == "t.ngc:1:8: expected an operator or ']', found '2'");
    CHECK(error_of("G1 X#<a>") == "t.ngc:1:5: parameter #<a> is not defined");
    CHECK(error_of("G1 X#1.5") ==
          "t.ngc:1:5: parameter number 1.5 is not a whole number from 1 to 5602");
    CHECK(error_of("G1 @5 ^90 @1") == "t.ngc:1:11: repeated word @ in one block");
    CHECK(error_of("G1 X5 ^90") == "t.ngc:1:7: polar coordinates (@ ^) and X or Y in one block");
    CHECK(error_of("#1") ==
          "t.ngc:1:3: expected '=' after #1 (a parameter is read only inside a value)");
    CHECK(error_of("G1 X[" + std::string(100, '[') + "1" + std::string(101, ']'))
              .find("nested more than 64") != std::string::npos);
}

TEST_CASE("G-code: parameters take effect after the line", "[gcode]") {
    // #1 is still 0 on its own line; 10 from the next.
    const Path p = run("#1=10 G1 Z-1 X#1\nG1 Y#1\n#<len>=[#1*2] #<_g>=3\nG1 X#<len> Y#<_g>\n");
    REQUIRE(p.subpaths.size() == 1);
    CHECK(last_point(p) == std::make_pair(20.0, 3.0));
    CHECK(last_point(run("#2=5 #5=7\nG1 Z-1\nG1 X##2\n")).first == Approx(7));
    CHECK(last_point(run("#<My Name>=4\nG1 Z-1\nG1 X#<myname>\n")).first ==
          Approx(4));  // blanks, case
}

TEST_CASE("G-code: subroutines with arguments", "[gcode]") {
    const std::string program =
        "o<square> sub\n"
        "  #<s> = #1\n"
        "  G1 X[#<_x0>+#<s>]\n"
        "  G1 Y#<s>\n"
        "  o<square> return [#<s>*4]\n"
        "o<square> endsub\n"
        "#<_x0>=0\n"
        "G1 Z-1\n"
        "#1=99\n"
        "o<square> call [5]\n"
        "G1 X#1 Y#<_value>\n"  // #1 restored after the call; the return value
        "M2\n";
    const Path p = run(program);
    CHECK(last_point(p) == std::make_pair(99.0, 20.0));
    CHECK(error_of("o100 call\n") == "t.ngc:1:1: O100 call: no such subroutine in this file");
    CHECK(error_of("o1 sub\no1 call\no1 endsub\nG1 Z-1\no1 call\n") ==
          "t.ngc:2:1: O1 call: calls nested more than 9 deep");
    CHECK(error_of("o1 sub\no2 sub\no2 endsub\no1 endsub\n") ==
          "t.ngc:2:1: O2 sub inside another block (define subroutines at the top level)");
    CHECK(error_of("o1 endsub\n") == "t.ngc:1:1: O1 endsub without an open O1 sub");
}

TEST_CASE("G-code: if and elseif", "[gcode]") {
    auto branch = [](int n) {
        return last_point(run("#1=" + std::to_string(n) +
                              "\nG1 Z-1\no1 if [#1 EQ 1]\nG1 X1\no1 elseif [#1 EQ 2]\nG1 X2\n"
                              "o1 else\nG1 X3\no1 endif\nG1 Y1\n"))
            .first;
    };
    CHECK(branch(1) == 1);
    CHECK(branch(2) == 2);
    CHECK(branch(7) == 3);
    CHECK(error_of("o1 if\no1 endif\nG1 Z-1 X1\n") == "t.ngc:1:1: O1 if needs a value in [ ]");
    CHECK(error_of("o1 if [1]\n") == "t.ngc:1:1: O1 if is never closed (no endif)");
}

TEST_CASE("G-code: loops", "[gcode]") {
    // 5 passes of while, 3 of do, 4 of repeat: 12 unit steps in X.
    const Path p =
        run("G1 Z-1\n#1=0\no1 while [#1 LT 5]\nG91 G1 X1\n#1=[#1+1]\no1 endwhile\n"
            "#1=0\no2 do\nG1 X1\n#1=[#1+1]\no2 while [#1 LT 3]\n"
            "o3 repeat [4]\nG1 X1\no3 endrepeat\nG90\n");
    CHECK(last_point(p).first == Approx(12));
    // break leaves at the third pass; continue skips the odd passes' moves.
    const Path q = run(
        "G1 Z-1 G91\n#1=0\no1 while [1]\n#1=[#1+1]\no2 if [#1 GT 3]\no1 break\no2 endif\nG1 X1\n"
        "o1 endwhile\n#2=0\no3 repeat [6]\n#2=[#2+1]\no4 if [#2 MOD 2]\no3 continue\no4 endif\n"
        "G1 Y1\no3 endrepeat\n");
    CHECK(last_point(q) == std::make_pair(3.0, 3.0));
}

TEST_CASE("G-code: a loop that never ends is an error", "[gcode]") {
    CHECK(error_of("G1 Z-1\no1 while [1]\nG1 X1\no1 endwhile\n") ==
          "t.ngc:2:1: O1 while: more than 1000000 loop passes in all (the reader's limit; a loop "
          "that never ends?)");
    CHECK(error_of("o7 repeat [1000000000]\no7 endrepeat\n") ==
          "t.ngc:1:1: O7 repeat: more than 1000000 loop passes in all (the reader's limit; a loop "
          "that never ends?)");
}

TEST_CASE("G-code: G92 offsets and G53", "[gcode]") {
    // After G92 X0 at X10 the program's X0 is the machine's X10.
    const Path p = run("G0 X10 Y5 Z-1\nG92 X0 Y0\nG1 X5 Y5\nG53 G1 X1 Y1\nG92.1\nG1 X2 Y2\n");
    REQUIRE(p.subpaths.size() == 1);
    const auto& pts = p.subpaths[0].points;
    CHECK(pts[1] == PathPoint{15, 10});  // lines only: a polyline of their ends
    CHECK(pts[2] == PathPoint{1, 1});
    CHECK(pts[3] == PathPoint{2, 2});
    CHECK(error_of("G92\n") == "t.ngc:1:1: G92 needs at least one axis word");
    CHECK(error_of("G92 G1 X1\n") ==
          "t.ngc:1:5: G10, G28, G30, G43.1 and G92 use the block's axis words: no motion code "
          "with them");
    CHECK(error_of("G91 G53 G1 X1\n") ==
          "t.ngc:1:5: G53 needs a G0 or G1 move in absolute mode (G90) in its block");
}

TEST_CASE("G-code: G28 and G30 travel home from #5161 and #5181", "[gcode]") {
    const Path p =
        run("#5161=50 #5162=60 #5181=7 #5182=8\nG1 Z-1\nG1 X1\nG28 X20\nG1 X2 Y2\nG30\nG1 X3 Y3\n");
    REQUIRE(p.subpaths.size() == 3);
    // G28 X20: through X20, then X to #5161; Y stays.
    CHECK(p.subpaths[1].points.front() == PathPoint{50, 0});
    CHECK(p.subpaths[2].points.front() == PathPoint{7, 8});
}

TEST_CASE("G-code: G4 dwell and M0 pause mark the next subpath", "[gcode]") {
    const Path p =
        run("G1 Z-1\nG1 X10\nG4 P1.5\nG1 X20\nG0 Z1\nG4 P2\nG0 X30\nM0\nG1 Z-1\nG1 X40\n");
    REQUIRE(p.subpaths.size() == 3);
    CHECK(p.subpaths[0].dwell_before == 0);
    CHECK(p.subpaths[1].dwell_before == 1.5);  // mid-stroke: the stroke ends, pen stays down
    CHECK(p.subpaths[1].dwell_pen_down);
    CHECK_FALSE(p.subpaths[1].pause_before);
    CHECK(p.subpaths[2].dwell_before == 2);
    CHECK_FALSE(p.subpaths[2].dwell_pen_down);
    CHECK(p.subpaths[2].pause_before);
}

TEST_CASE("G-code: skipped codes warn once each", "[gcode]") {
    GcodeReadInfo info;
    const Path p = run("$H\nM6 T1\nG1 Z-1\nG1 X1 M8\nM6\nM300 S440 P200\n$X\n", {}, &info);
    REQUIRE(info.warnings.size() == 4);
    CHECK(info.warnings[0] ==
          "t.ngc:1:1: grbl '$' line skipped; later ones are skipped without a warning");
    CHECK(info.warnings[1] ==
          "t.ngc:2:1: M6 skipped (it means nothing to this machine); later ones are skipped "
          "without a warning");
    CHECK(info.warnings[2].rfind("t.ngc:4:7: M8 skipped", 0) == 0);
    CHECK(info.warnings[3].rfind("t.ngc:6:1: M300 skipped", 0) == 0);
    CHECK(last_point(p).first == 1);
    CHECK(error_of("G1 Z-1 X1\nM223\n") ==
          "t.ngc:2:1: unsupported M code M223 (skip it with --ignore-code M223 if it means nothing "
          "here)");
    GcodeOptions o;
    o.ignore_codes = {"m0123", "G43"};
    GcodeReadInfo more;
    run("G1 Z-1\nG1 X1\nM123\nG43 H1\n", o, &more);
    CHECK(more.warnings.size() == 2);
    o.ignore_codes = {"X5"};
    CHECK_THROWS_AS(run("G1 Z-1 X1\n", o), std::invalid_argument);
}

TEST_CASE("G-code: unsupported planes and cycles", "[gcode]") {
    CHECK(error_of("G18 G2 X1 K1\n") ==
          "t.ngc:1:5: G18 arcs move Z, which is not one of this machine's axes (XY)");
    CHECK(error_of("G81 X1 Y1 Z-1 R1\n") ==
          "t.ngc:1:1: G81: canned cycles need a machine whose moves keep their order "
          "(--gcode-pen machine, the default on a machine with a Z axis)");
    CHECK(error_of("G1 Z-1\nG1 X1\nM2\nG1 X[1/0]\n") == "no error");  // nothing after M2 is read
}

TEST_CASE("G-code: pen mode motion", "[gcode]") {
    GcodeOptions o;
    o.pen = PenControl::kMotion;
    const Path p = run("G0 X1 Y1\nG1 X5\nG1 Y5\nG0 X10\nG2 X20 I5\n", o);
    REQUIRE(p.subpaths.size() == 2);
    CHECK(p.subpaths[0].points.front() == PathPoint{1, 1});
    CHECK(p.subpaths[1].points.front() == PathPoint{10, 5});
}

TEST_CASE("G-code: pen mode auto says why", "[gcode]") {
    GcodeOptions o;
    o.pen = PenControl::kAuto;
    GcodeReadInfo info;
    run("G0 Z5\nG1 X1\nG1 Z-1\nG1 X5\n", o, &info);
    CHECK(info.pen == PenControl::kZ);
    CHECK(info.pen_reason == "auto: Z goes both above and to or below --gcode-z-down 0 mm");
    const Path s = run("G0 Z5\nG1 X1\nM3\nG1 X5\nM5\nG1 X9\n", o, &info);
    CHECK(info.pen == PenControl::kSpindle);
    CHECK(info.pen_reason == "auto: M3/M4 appear and Z never crosses --gcode-z-down 0 mm");
    REQUIRE(s.subpaths.size() == 1);
    CHECK(s.subpaths[0].points.back() == PathPoint{5, 0});
    const Path m = run("G0 X1\nG1 X5\nG0 X7\nG1 X9\n", o, &info);
    CHECK(info.pen == PenControl::kMotion);
    CHECK(info.pen_reason ==
          "auto: no M3/M4 and Z never crosses --gcode-z-down 0 mm, so G1 draws and G0 travels");
    CHECK(m.subpaths.size() == 2);
    run("G1 Z-1\nG1 X5\n", {}, &info);
    CHECK(info.pen_reason == "as asked");
}

TEST_CASE("G-code: loop and piece budgets", "[gcode]") {
    // The inner loop's passes count too: 2000 x 1000 passes are too many.
    CHECK(error_of("G1 Z-1\no1 repeat [2000]\no2 repeat [1000]\no2 endrepeat\no1 endrepeat\n") ==
          "t.ngc:3:1: O2 repeat: more than 1000000 loop passes in all (the reader's limit; a "
          "loop that never ends?)");
    // Four lines a pass: the 500,001st pass draws the 2,000,001st piece.
    CHECK(error_of("G1 Z-1\no1 repeat [600000]\nG1 X1\nX0\nX1\nX0\no1 endrepeat\n") ==
          "t.ngc:3:1: more than 2000000 curve pieces drawn (the reader's limit)");
}

TEST_CASE("G-code: budgets smaller than the reader's", "[gcode]") {
    GcodeOptions options;
    options.budget.loop_passes = 10;
    CHECK(error_of("G1 Z-1\no1 repeat [11]\no1 endrepeat\n", options) ==
          "t.ngc:2:1: O1 repeat: more than 10 loop passes in all (the reader's limit; a loop "
          "that never ends?)");
    CHECK(run("G1 Z-1\no1 repeat [10]\nG91 G1 X1\no1 endrepeat\n", options).subpaths.size() == 1);
    options = {};
    options.budget.blocks = 3;
    CHECK(error_of("G1 Z-1\nG1 X1\nG1 X2\nG1 X3\n", options) ==
          "t.ngc:4:1: more than 3 lines or 500000000 characters run (the reader's limit; a loop "
          "that never ends?)");
    options = {};
    options.budget.pieces = 2;
    CHECK(error_of("G1 Z-1\nG1 X1\nX2\nX3\n", options) ==
          "t.ngc:4:1: more than 2 curve pieces drawn (the reader's limit)");
    options = {};
    options.budget.characters = 0;
    CHECK_THROWS_AS(run("G1 Z-1 X1\n", options), std::invalid_argument);
}

TEST_CASE("G-code: a setting's own line reads the old value", "[gcode]") {
    const Path p = run("#1=10\n#1=20 G1 Z-1 Y#1\nG1 X#1\n");
    REQUIRE(p.subpaths.size() == 1);
    CHECK(p.subpaths[0].points.front() == PathPoint{0, 10});
    CHECK(last_point(p) == std::make_pair(20.0, 10.0));
}

TEST_CASE("G-code: G92.2 and G92.3, G28.1 and G30.1", "[gcode]") {
    // G92.2 drops the offset but keeps #5211..; G92.3 takes it back from them.
    const Path p = run("G0 X10 Z-1\nG92 X0\nG92.2\nG1 X1\nG92.3\nG1 X1\n");
    CHECK(p.subpaths[0].points[1] == PathPoint{1, 0});
    CHECK(p.subpaths[0].points[2] == PathPoint{11, 0});
    // G28.1 stores where the machine is (mm, also under G20); G28 goes back there.
    const Path q = run("G20 G0 X1 Y2 Z-1\nG28.1\nG0 X0 Y0\nG28\nG1 X[#5161/25.4 + 1]\n");
    CHECK(q.subpaths[0].points.front() == PathPoint{25.4, 50.8});
    CHECK(last_point(q).first == Approx(50.8));
}

TEST_CASE("G-code: O-word nesting budget", "[gcode]") {
    std::string deep;
    for (int k = 0; k < 1001; ++k) deep += "o" + std::to_string(k) + " if [1]\n";
    CHECK(error_of(deep) == "t.ngc:1001:1: O-word blocks nested more than 1000 deep");
}

TEST_CASE("G-code: call arguments zero the rest, repeat rounds", "[gcode]") {
    // #2 is 7 before the call; the call gives only #1, so #2 reads 0 inside and 7 after.
    const Path p = run("o1 sub\nG1 X#1 Y#2\no1 endsub\n#2=7\nG1 Z-1\no1 call [3]\nG1 Y#2\n");
    REQUIRE(p.subpaths.size() == 1);
    CHECK(p.subpaths[0].points[1] == PathPoint{3, 0});
    CHECK(last_point(p) == std::make_pair(3.0, 7.0));
    // repeat [2.6] runs 3 times, [2.5] twice (halves to even), [0.4] never.
    auto passes = [](const std::string& count) {
        return last_point(
                   run("G1 Z-1\nG1 Y1\nG91\no1 repeat [" + count + "]\nG1 X1\no1 endrepeat\n"))
            .first;
    };
    CHECK(passes("2.6") == 3);
    CHECK(passes("2.5") == 2);
    CHECK(passes("0.4") == 0);
}
