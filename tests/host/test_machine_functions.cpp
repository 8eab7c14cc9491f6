// A machine's spindle and coolant (G-code M3/M4/M5, M7/M8/M9, and the stops of M6 and M0):
// the reader gives each subpath the machine functions in force while it moves and while its
// pause holds, in LinuxCNC's order within a block; the planner switches them only at rest,
// with a still span that carries them, lasting the profile's spin-up when the spindle starts.
#include <catch2/catch.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/span.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

constexpr std::uint8_t kCw = kOutputSpindle;
constexpr std::uint8_t kCcw = kOutputSpindle | kOutputSpindleReverse;

GcodeOptions router() {
    GcodeOptions o;
    o.axes = "XYZ";
    o.pen = PenControl::kMachine;
    o.rapid_feed = 150;
    return o;
}

Path gcode(const std::string& text, const GcodeOptions& options = router()) {
    return parse_gcode_path(text, "t.ngc", options);
}

std::string error_of(const std::string& text) {
    try {
        gcode(text);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

std::vector<unsigned> outputs_of(const Path& p) {
    std::vector<unsigned> out;
    for (const Subpath& s : p.subpaths) out.push_back(s.outputs);
    return out;
}

MachineProfile router_profile(double spin_up) {
    MachineProfile p;
    p.axes.push_back({"x", 100, 1000});
    p.axes.push_back({"y", 100, 1000});
    p.axes.push_back({"z", 40, 500});
    p.feed = 20;
    p.travel_feed = 100;
    p.pen_down_delay = p.pen_up_delay = 0;
    p.chord_tolerance = 0.01;
    p.spindle.present = true;
    p.spindle.spin_up = spin_up;
    return p;
}

bool still(const CoreSpan& s) {
    for (const auto& c : s.control) {
        if (c[0] != c[1] || c[2] != 0 || c[3] != 0) return false;
    }
    return true;
}

}  // namespace

TEST_CASE("machine functions: M3 M4 M5 M7 M8 M9 set the subpaths' outputs", "[gcode][machine]") {
    const Path p = gcode(
        "G1 X1 F600\nS1000 M3\nG1 X10\nM8\nG1 X20\nM7 M8\nG1 X30\nM9 M4\nG1 X40\nM5\nG1 X50\n");
    CHECK(outputs_of(p) == std::vector<unsigned>{0, kCw, kCw | kOutputFlood,
                                                 kCw | kOutputFlood | kOutputMist, kCcw, 0});
    // Unchanged codes split nothing: M3 twice, M9 with no coolant on.
    CHECK(gcode("M3\nG1 X10 F600\nM3 M9\nG1 X20\n").subpaths.size() == 1);
    CHECK(error_of("M7 M9\n") ==
          "t.ngc:1:4: M7 and M9 are in the same modal group (one per block)");
    CHECK(error_of("M3 M5\n") ==
          "t.ngc:1:4: M3 and M5 are in the same modal group (one per block)");
}

TEST_CASE("machine functions: a pause holds with what the program left on", "[gcode][machine]") {
    SECTION("M5 M0: the spindle stops before the pause") {
        const Path p = gcode("M3 M8\nG1 X10 F600\nM5 M0\nG1 X20\n");
        REQUIRE(p.subpaths.size() == 2);
        CHECK(p.subpaths[1].pause_before);
        CHECK(p.subpaths[1].pause_outputs == kOutputFlood);
        CHECK(p.subpaths[1].outputs == kOutputFlood);
    }
    SECTION("M0 then M3: the spindle starts after it") {
        const Path p = gcode("G1 X10 F600\nM0\nM3\nG1 X20\n");
        REQUIRE(p.subpaths.size() == 2);
        CHECK(p.subpaths[1].pause_outputs == 0);
        CHECK(p.subpaths[1].outputs == kCw);
    }
    SECTION("M1 with the spindle on: it runs through the pause") {
        const Path p = gcode("M3\nG1 X10 F600\nM1\nG1 X20\n");
        REQUIRE(p.subpaths.size() == 2);
        CHECK(p.subpaths[1].pause_outputs == kCw);
        CHECK(p.subpaths[1].outputs == kCw);
    }
    SECTION("M6 stops the spindle, keeps the coolant; M3 in its block follows the change") {
        Path p = gcode("M3 M8\nG1 X10 F600\nT1 M6\nG1 X20\n");
        REQUIRE(p.subpaths.size() == 2);
        CHECK(p.subpaths[1].pause_outputs == kOutputFlood);
        CHECK(p.subpaths[1].outputs == kOutputFlood);
        p = gcode("M4\nG1 X10 F600\nT1 M6 M3\nG1 X20\n");
        REQUIRE(p.subpaths.size() == 2);
        CHECK(p.subpaths[1].pause_outputs == 0);
        CHECK(p.subpaths[1].outputs == kCw);
    }
    SECTION("M70 and M72 save and restore them") {
        const Path p = gcode("F600 M3 M8\nM70\nM5 M9\nG1 X10\nM72\nG1 X20\n");
        CHECK(outputs_of(p) == std::vector<unsigned>{0, kCw | kOutputFlood});
    }
}

TEST_CASE("machine functions: G86 stops the spindle at the hole's bottom", "[gcode][machine]") {
    const Path p = gcode("M4\nG0 Z5\nG98 G86 X10 Y0 Z-2 R1 P0.5 F120\nG80\nG1 X20 F600\n");
    // Rapid to Z5; the cycle rapids over the hole and down to R; feed to the bottom; out with the
    // spindle stopped; then it runs again (counter-clockwise) for the next move.
    std::vector<unsigned> outputs;
    std::vector<bool> travel;
    for (const Subpath& s : p.subpaths) {
        outputs.push_back(s.outputs);
        travel.push_back(s.travel);
    }
    CHECK(outputs == std::vector<unsigned>{kCcw, kCcw, kCcw, 0, kCcw});
    CHECK(travel == std::vector<bool>{true, true, false, true, false});
}

TEST_CASE("machine functions: a plotter skips coolant and keeps M3 as its pen", "[gcode]") {
    GcodeReadInfo info;  // a pen plotter, Z as the pen
    const Path p =
        parse_gcode_path("M8\nG0 X0 Y0\nG1 Z-1 F600\nG1 X10\nM9\n", "t.ngc", GcodeOptions{}, &info);
    CHECK(outputs_of(p) == std::vector<unsigned>{0});
    REQUIRE(!info.warnings.empty());
    CHECK(info.warnings.front().find("M8") != std::string::npos);
}

TEST_CASE("machine functions: the planner switches them at rest, after the spin-up",
          "[gcode][machine][planner]") {
    const MachineProfile profile = router_profile(0.5);
    const Path p = gcode("G0 Z5\nS9000 M3 M8\nG1 Z-1 F300\nG1 X20\nM5 M0\nG1 X30\nM4\nG1 X40\n");
    const Plan plan = plan_path(to_bezier_segments(p), profile);
    // Walk the spans: every change of the machine functions is a still span that starts at
    // rest; a start of the spindle (off to on, or a reversal) lasts at least the spin-up.
    std::uint8_t last = 0;
    std::vector<std::uint8_t> changes;
    std::uint64_t spin_up_ticks = 0;
    bool pause_seen = false;
    for (std::size_t i = 0; i < plan.spans.size(); ++i) {
        const CoreSpan& s = plan.spans[i];
        INFO("span " << i);
        if (s.machine != last) {
            REQUIRE(still(s));
            for (const auto& c : plan.spans[i - (i > 0 ? 1 : 0)].control) REQUIRE(c[3] == 0);
            changes.push_back(s.machine);
            const bool starts =
                (s.machine & kOutputSpindle) != 0 &&
                ((last & kOutputSpindle) == 0 || ((s.machine ^ last) & kOutputSpindleReverse) != 0);
            if (starts) {
                std::uint64_t rest = 0;  // the still spans from here, all with the new value
                for (std::size_t k = i; k < plan.spans.size() && still(plan.spans[k]) &&
                                        plan.spans[k].machine == s.machine;
                     ++k) {
                    rest += plan.spans[k].ticks;
                }
                CHECK(rest >= 500);
                spin_up_ticks += 500;
            }
            last = s.machine;
        }
        if (s.pause_after) {
            pause_seen = true;
            CHECK(s.machine == kOutputFlood);  // M5 before M0: the pause holds without spindle
        }
    }
    CHECK(pause_seen);
    CHECK(changes ==
          std::vector<std::uint8_t>{kCw | kOutputFlood, kOutputFlood, kCcw | kOutputFlood});
    CHECK(spin_up_ticks == 1000);
    // Without a spin-up each change is one still tick: the two starts cost 2 x 499 ticks.
    const Plan none = plan_path(to_bezier_segments(p), router_profile(0));
    CHECK(plan.total_ticks - none.total_ticks == 998);
}
