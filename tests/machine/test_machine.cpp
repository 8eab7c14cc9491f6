// Machine profile reader: defaults, every field, and each impossible value's own message.
#include <catch2/catch.hpp>
#include <cmath>

#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/machine.hpp"

using namespace pathstream::host;

namespace {
const char* kAxes = R"("axes": [{"name": "x", "max_velocity": 100, "max_acceleration": 1000}])";

std::string error_of(const std::string& text) {
    try {
        parse_machine_profile(text, "m.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}
}  // namespace

TEST_CASE("a minimal profile takes the documented defaults", "[host][machine]") {
    const MachineProfile p = parse_machine_profile(std::string("{") + kAxes + "}", "m.json");
    REQUIRE(p.axes.size() == 1);
    CHECK(p.axes[0].name == "x");
    CHECK(p.axes[0].max_velocity == 100);
    CHECK(p.axes[0].max_acceleration == 1000);
    CHECK(p.mm_per_lsb == 0.001);
    CHECK(p.tick_hz == 1000);
    CHECK(p.ticks_per_span == 8);
    CHECK(p.source == "m.json");
    CHECK(p.corner_stop_angle < 0);  // the planner's own angle
}

TEST_CASE("corner_stop_angle is read in degrees, 1 to 180", "[host][machine]") {
    const MachineProfile p =
        parse_machine_profile(std::string("{") + kAxes + ", \"corner_stop_angle\": 45}", "m.json");
    CHECK(p.corner_stop_angle == Approx(std::atan(1.0)).epsilon(1e-12));  // 45 degrees: pi / 4
    CHECK(error_of(std::string("{") + kAxes + ", \"corner_stop_angle\": 0.5}") ==
          "m.json:1:95: corner_stop_angle 0.5 degrees is impossible (allowed: >= 1 and <= 180 "
          "degrees)");
    CHECK(error_of(std::string("{") + kAxes + ", \"corner_stop_angle\": 181}") ==
          "m.json:1:95: corner_stop_angle 181 degrees is impossible (allowed: >= 1 and <= 180 "
          "degrees)");
}

TEST_CASE("the example profile loads", "[host][machine]") {
    const MachineProfile p =
        load_machine_profile(PATHSTREAM_SOURCE_DIR "/examples/machines/pen_plotter.json");
    CHECK(p.axes.size() == 2);
    CHECK(p.feed == 80);
    CHECK(p.pen_down_delay == 0.08);
}

TEST_CASE("impossible profiles are refused with the place and the reason", "[host][machine]") {
    CHECK(error_of("{\"axes\": []}") ==
          "m.json:1:10: axes must be an array of 1 to 8 axis objects");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 0, "max_acceleration": 1}]})") ==
          "m.json:1:41: max_velocity 0 mm/s is impossible (allowed: > 0 and <= 100000 mm/s)");
    CHECK(
        error_of(R"({"axes": [{"name": "x", "max_velocity": 1, "max_acceleration": -5}]})") ==
        "m.json:1:64: max_acceleration -5 mm/s^2 is impossible (allowed: > 0 and <= 1e+07 mm/s^2)");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 1}]})") ==
          "m.json:1:11: axis has no \"max_acceleration\"");
    CHECK(error_of(std::string("{") + kAxes + ", \"tick_hz\": 5}") ==
          "m.json:1:85: tick_hz 5 Hz is impossible (allowed: >= 10 and <= 100000 Hz)");
    CHECK(error_of(std::string("{") + kAxes + ", \"ticks_per_span\": 2.5}") ==
          "m.json:1:92: ticks_per_span must be a whole number");
    CHECK(error_of(std::string("{") + kAxes + ", \"chord_tolerance\": 0.0001}") ==
          "m.json:1:93: chord_tolerance 0.0001 mm is below half an LSB (0.0005 mm): integer "
          "setpoints cannot meet it");
    CHECK(error_of(std::string("{") + kAxes + ", \"speed\": 3}") ==
          "m.json:1:83: unknown key \"speed\" (expected one of: axes, chord_tolerance, "
          "corner_stop_angle, feed, gpio, input_shaper, "
          "layer_feeds, mm_per_lsb, output_coils, "
          "pen_down_delay, pen_up_delay, plan_for_shaper, resonance, spindle, tick_hz, "
          "ticks_per_span, "
          "travel_feed)");
    CHECK(error_of(std::string("{") + kAxes + ", \"spindle\": {\"spin_up\": -1}}") ==
          "m.json:1:97: spin_up -1 s is impossible (allowed: >= 0 and <= 600 s)");
    CHECK(error_of(std::string("{") + kAxes + ", \"spindle\": {\"rpm\": 1}}") ==
          "m.json:1:93: unknown key \"rpm\" (expected one of: spin_up)");
    CHECK(error_of(std::string("{") + kAxes + ", \"spindle\": 2}") ==
          "m.json:1:85: spindle must be an object like {\"spin_up\": 2}");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 1, "max_acceleration": 1},
                              {"name": "x", "max_velocity": 1, "max_acceleration": 1}]})") ==
          "m.json:2:40: axis name \"x\" is used twice");
}

TEST_CASE("profiles the planner cannot work with are refused at the value, with the range",
          "[host][machine]") {
    // Speeds below 1 LSB per span (0.125 mm/s at 0.001 mm, 1000 Hz, 8 ticks per span).
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 1e-300, "max_acceleration": 1000}]})") ==
        "m.json:1:41: max_velocity 1e-300 mm/s is below 1 LSB per span (0.001 mm/LSB, 1000 Hz, 8 "
        "ticks per span): "
        "planning would crawl (allowed: >= 0.125 mm/s; or raise ticks_per_span, or lower tick_hz)");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 0.1, "max_acceleration": 1000}]})") !=
          "no error");
    CHECK(
        error_of(R"({"axes": [{"name": "x", "max_velocity": 0.125, "max_acceleration": 1000}]})") ==
        "no error");
    // Accelerations that cannot gain that speed within a span (15.625 mm/s^2 here).
    CHECK(
        error_of(R"({"axes": [{"name": "x", "max_velocity": 100, "max_acceleration": 1e-300}]})") ==
        "m.json:1:66: max_acceleration 1e-300 mm/s^2 cannot gain 1 LSB per span of speed within "
        "one span "
        "(0.001 mm/LSB, 1000 Hz, 8 ticks per span) (allowed: >= 15.625 mm/s^2; or raise "
        "ticks_per_span, or "
        "lower tick_hz)");
    CHECK(
        error_of(R"({"axes": [{"name": "x", "max_velocity": 100, "max_acceleration": 15.625}]})") ==
        "no error");
    // The same acceleration is fine with longer spans.
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 100, "max_acceleration": 1}], "ticks_per_span": 32})") ==
        "no error");
    // Feeds too.
    CHECK(error_of(std::string("{") + kAxes + ", \"feed\": 0.01}") ==
          "m.json:1:82: feed 0.01 mm/s is below 1 LSB per span (0.001 mm/LSB, 1000 Hz, 8 ticks per "
          "span): planning "
          "would crawl (allowed: >= 0.125 mm/s)");
    CHECK(error_of(std::string("{") + kAxes + ", \"travel_feed\": 1e-9}")
              .find("m.json:1:89: travel_feed 1e-09 mm/s") == 0);
    CHECK(error_of(std::string("{") + kAxes + ", \"layer_feeds\": {\"red\": 1e-9}}")
              .find("m.json:1:97: layer feed 1e-09 mm/s is below 1 LSB per span") == 0);
    // On a fine grid 1 LSB per span can be slower than any drawing should plan at (1.25e-6
    // mm/s at 1e-6 mm, 10 Hz: 179 mm of star.csv would take 4.5 years): 1 mm an hour is the
    // floor then, for every speed.
    const std::string fine =
        R"("mm_per_lsb": 1e-6, "tick_hz": 10, "feed": 0.001, "travel_feed": 0.001)";
    CHECK(error_of(
              R"({"axes": [{"name": "x", "max_velocity": 1.25e-6, "max_acceleration": 1000}], )" +
              fine + "}") ==
          "m.json:1:41: max_velocity 1.25e-06 mm/s is below 1 mm an hour: a drawing would plan and "
          "run for days "
          "(allowed: >= 0.000277778 mm/s)");
    CHECK(
        error_of(R"({"axes": [{"name": "x", "max_velocity": 0.001, "max_acceleration": 1000}], )" +
                 fine + "}") == "no error");
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 0.001, "max_acceleration": 1000}], "mm_per_lsb": 1e-6, )"
            R"("tick_hz": 10, "feed": 0.0001})")
            .find("feed 0.0001 mm/s is below 1 mm an hour") != std::string::npos);
}

TEST_CASE("spans longer than the work area at full speed are refused", "[host][machine]") {
    // examples/machines/a3_plotter.json with the documented maximum ticks_per_span: one span at
    // 250 mm/s crosses 16,384 mm of a 430 mm travel.
    const char* a3 =
        R"({"axes": [{"name": "x", "max_velocity": 250, "max_acceleration": 3000, "travel": [0, 430]},
                                  {"name": "y", "max_velocity": 250, "max_acceleration": 3000, "travel": [0, 297]}],
                         "ticks_per_span": 65536})";
    CHECK(error_of(a3) ==
          "m.json:3:44: ticks_per_span 65536 is too long: a span of 65536 ticks at axis x's "
          "max_velocity 250 mm/s "
          "crosses 16384 mm, more than its travel (430 mm) (allowed: 1 .. 1720 ticks)");
    // Without travel, the device's position range (2^28 LSB: 268 m at 1 um) bounds a span only
    // at hundreds of metres: there a span lasts no longer than the axis's stop from full speed
    // (1000 mm/s at 3000 mm/s^2: 0.333 s, 333 ticks at 1 kHz).
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 1000, "max_acceleration": 3000}], "ticks_per_span": 65536})") ==
        "m.json:1:93: ticks_per_span 65536 is too long: a span of 65536 ticks (65.536 s) outlasts "
        "axis x's stop from "
        "its max_velocity 1000 mm/s at its max_acceleration 3000 mm/s^2 (0.333333 s), and the axis "
        "has no travel to "
        "bound it (allowed: 1 .. 333 ticks)");
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 1000, "max_acceleration": 3000}], "ticks_per_span": 333})") ==
        "no error");
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 1000, "max_acceleration": 3000}], "ticks_per_span": 334})") !=
        "no error");
    // Never below the default span (a fast stop: 10 mm/s at 3000 mm/s^2 takes 3.3 ticks) ...
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 10, "max_acceleration": 3000}], "ticks_per_span": 8})") ==
        "no error");
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 10, "max_acceleration": 3000}], "ticks_per_span": 9})")
            .find("(allowed: 1 .. 8 ticks)") != std::string::npos);
    // ... nor below the shortest span the floors allow (0.01 mm/s moves 1 LSB in 100 ticks).
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 0.01, "max_acceleration": 1000}], "ticks_per_span": 100})") ==
        "no error");
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 0.01, "max_acceleration": 1000}], "ticks_per_span": 101})")
            .find("(allowed: 1 .. 100 ticks)") != std::string::npos);
    // An axis with travel is bounded by its travel only (the a3 plotter above allows 1720).
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 250, "max_acceleration": 3000, "travel": [0, 430]}],
                       "ticks_per_span": 1720})") == "no error");
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 1000, "max_acceleration": 3000}], "mm_per_lsb": 0.00001,
                       "ticks_per_span": 65536})")
            .find("m.json:2:42: ticks_per_span 65536 is too long: a span of 65536 ticks at axis "
                  "x's max_velocity 1000 "
                  "mm/s crosses 65536 mm, more than the device's position range (2684.35 mm)") ==
        0);
    // The default span length: reported at the velocity that is too fast for it.
    CHECK(
        error_of(
            R"({"axes": [{"name": "x", "max_velocity": 99999, "max_acceleration": 3000, "travel": [0, 100]}]})") ==
        "m.json:1:41: max_velocity 99999 mm/s is too fast for spans of 8 ticks: a span of 8 ticks "
        "at axis x's "
        "max_velocity 99999 mm/s crosses 799.992 mm, more than its travel (100 mm) (allowed: <= "
        "12500 mm/s)");
}
