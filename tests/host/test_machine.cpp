// Machine profile reader: defaults, every field, and each impossible value's own message.
#include <catch2/catch.hpp>

#include "pathstream/host/input_error.hpp"
#include "pathstream/host/machine.hpp"

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
}

TEST_CASE("the example profile loads", "[host][machine]") {
    const MachineProfile p = load_machine_profile(PATHSTREAM_SOURCE_DIR "/examples/machines/pen_plotter.json");
    CHECK(p.axes.size() == 2);
    CHECK(p.feed == 80);
    CHECK(p.pen_down_delay == 0.08);
}

TEST_CASE("impossible profiles are refused with the place and the reason", "[host][machine]") {
    CHECK(error_of("{\"axes\": []}") == "m.json:1:10: axes must be an array of 1 to 8 axis objects");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 0, "max_acceleration": 1}]})") ==
          "m.json:1:41: max_velocity 0 mm/s is impossible (allowed: > 0 and <= 100000 mm/s)");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 1, "max_acceleration": -5}]})") ==
          "m.json:1:64: max_acceleration -5 mm/s^2 is impossible (allowed: > 0 and <= 1e+07 mm/s^2)");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 1}]})") == "m.json:1:11: axis has no \"max_acceleration\"");
    CHECK(error_of(std::string("{") + kAxes + ", \"tick_hz\": 5}") ==
          "m.json:1:85: tick_hz 5 Hz is impossible (allowed: >= 10 and <= 100000 Hz)");
    CHECK(error_of(std::string("{") + kAxes + ", \"ticks_per_span\": 2.5}") ==
          "m.json:1:92: ticks_per_span must be a whole number");
    CHECK(error_of(std::string("{") + kAxes + ", \"chord_tolerance\": 0.0001}") ==
          "m.json:1:93: chord_tolerance 0.0001 mm is below half an LSB (0.0005 mm): integer setpoints cannot meet it");
    CHECK(error_of(std::string("{") + kAxes + ", \"speed\": 3}") ==
          "m.json:1:83: unknown key \"speed\" (expected one of: axes, chord_tolerance, feed, gpio, layer_feeds, mm_per_lsb, "
          "pen_down_delay, pen_up_delay, tick_hz, ticks_per_span, travel_feed)");
    CHECK(error_of(R"({"axes": [{"name": "x", "max_velocity": 1, "max_acceleration": 1},
                              {"name": "x", "max_velocity": 1, "max_acceleration": 1}]})") ==
          "m.json:2:40: axis name \"x\" is used twice");
}
