// The machine profile's "gpio" object: chip, lines by offset or name, active-low, bias, limit
// switches per axis and side, homing, the spindle and coolant lines; the "output_coils" object
// (a Modbus module's coils for the same functions); each bad value with its file:line:col.
#include <catch2/catch.hpp>
#include <string>

#include "pathstream/machine/machine.hpp"
#include "profile_text.hpp"

using namespace pathstream::host;

namespace {
const char* kAxes = pathstream::test::kTwoAxes;

// Line 3 of the document starts with `"gpio": ` (8 columns) before the object.
std::string with_gpio(const std::string& gpio) {
    return pathstream::test::with_key("gpio", gpio);
}

std::string error_of(const std::string& text) {
    return pathstream::test::profile_error(text);
}
}  // namespace

TEST_CASE("gpio profile: absent means no gpio", "[host][gpio][machine]") {
    const MachineProfile p = parse_machine_profile(std::string("{") + kAxes + "}", "m.json");
    CHECK_FALSE(p.gpio.present);
}

TEST_CASE("gpio profile: every field", "[host][gpio][machine]") {
    const MachineProfile p = parse_machine_profile(with_gpio(R"({
        "chip": "pathstream-sim",
        "enable": {"line": 1},
        "estop": {"line": "estop", "active_low": true, "bias": "pull-up"},
        "pen": {"line": "pen-lift"},
        "limits": {"x-": {"line": 3}, "y+": {"line": "limit-y", "active_low": true, "bias": "disable"}},
        "home": {"x": {"switch": "x-", "search_velocity": 10, "latch_velocity": 1, "backoff": 2,
                       "max_travel": 300, "position": -5}}})"),
                                                   "m.json");
    const GpioConfig& g = p.gpio;
    REQUIRE(g.present);
    CHECK(g.chip == "pathstream-sim");
    CHECK(g.has_enable);
    CHECK(g.enable.line == "1");
    CHECK_FALSE(g.enable.active_low);
    CHECK(g.enable.bias == "as-is");
    CHECK(g.estop.line == "estop");
    CHECK(g.estop.active_low);
    CHECK(g.estop.bias == "pull-up");
    CHECK(g.pen.line == "pen-lift");
    REQUIRE(g.limits.size() == 2);
    CHECK(g.limits[0].first == "x-");
    CHECK(g.limits[0].second.line == "3");
    CHECK(g.limits[1].first == "y+");
    CHECK(g.limits[1].second.active_low);
    CHECK(g.limits[1].second.bias == "disable");
    REQUIRE(g.home.size() == 1);
    CHECK(g.home[0].axis == "x");
    CHECK(g.home[0].switch_name == "x-");
    CHECK(g.home[0].search_velocity == 10);
    CHECK(g.home[0].latch_velocity == 1);
    CHECK(g.home[0].backoff == 2);
    CHECK(g.home[0].max_travel == 300);
    CHECK(g.home[0].position == -5);
}

TEST_CASE("gpio profile: bad values are refused with the place and the reason",
          "[host][gpio][machine]") {
    CHECK(error_of(with_gpio(R"({"enable": {"line": 1}})")) == "m.json:3:9: gpio has no \"chip\"");
    CHECK(error_of(with_gpio(R"({"chip": ""})")) ==
          "m.json:3:18: chip must be a chip name, path, number or label (non-empty string)");
    CHECK(error_of(with_gpio(R"({"chip": "c", "beeper": {"line": 1}})")) ==
          "m.json:3:33: unknown key \"beeper\" (expected one of: chip, enable, estop, flood, "
          "home, limits, mist, pen, spindle, spindle_reverse)");
    CHECK(error_of(with_gpio(R"({"chip": "c", "enable": {"line": -1}})")) ==
          "m.json:3:42: line offset must be 0..65535");
    CHECK(error_of(with_gpio(R"({"chip": "c", "enable": {"line": 1.5}})")) ==
          "m.json:3:42: line must be an offset (whole number) or a line name (string)");
    CHECK(error_of(with_gpio(R"({"chip": "c", "enable": {}})")) ==
          "m.json:3:33: enable has no \"line\"");
    CHECK(error_of(with_gpio(R"({"chip": "c", "estop": {"line": 2, "bias": "up"}})")) ==
          "m.json:3:52: bias must be one of: as-is, disable, pull-up, pull-down");
    CHECK(error_of(with_gpio(R"({"chip": "c", "estop": {"line": 2, "active_low": 1}})")) ==
          "m.json:3:58: active_low must be true or false");
    CHECK(error_of(with_gpio(R"({"chip": "c", "limits": {"z-": {"line": 2}}})")) ==
          "m.json:3:40: unknown key \"z-\" (expected one of: x+, x-, y+, y-)");
    CHECK(error_of(with_gpio(R"({"chip": "c", "limits": {"x-": {"line": 2}},
        "home": {"x": {"switch": "x+", "search_velocity": 10, "latch_velocity": 1, "backoff": 2, "max_travel": 300}}})")) ==
          "m.json:4:34: switch \"x+\" is not in gpio.limits");
    CHECK(error_of(with_gpio(R"({"chip": "c", "limits": {"x-": {"line": 2}},
        "home": {"x": {"switch": "y-", "search_velocity": 10, "latch_velocity": 1, "backoff": 2, "max_travel": 300}}})")) ==
          "m.json:4:34: switch must be \"x-\" or \"x+\"");
    CHECK(error_of(with_gpio(R"({"chip": "c", "limits": {"x-": {"line": 2}},
        "home": {"x": {"switch": "x-", "search_velocity": 500, "latch_velocity": 1, "backoff": 2, "max_travel": 300}}})")) ==
          "m.json:4:59: search_velocity 500 mm/s is impossible (allowed: > 0 and <= 100 mm/s)");
    CHECK(error_of(with_gpio(R"({"chip": "c", "limits": {"x-": {"line": 2}},
        "home": {"x": {"switch": "x-", "search_velocity": 10, "latch_velocity": 20, "backoff": 2, "max_travel": 300}}})")) ==
          "m.json:4:81: latch_velocity 20 mm/s is impossible (allowed: > 0 and <= 10 mm/s)");
    CHECK(error_of(with_gpio(R"({"chip": "c", "limits": {"x-": {"line": 2}},
        "home": {"x": {"switch": "x-", "search_velocity": 10, "latch_velocity": 1, "backoff": 2}}})")) ==
          "m.json:4:23: homing has no \"max_travel\"");
    CHECK(error_of(with_gpio(R"({"chip": "c", "limits": {"x-": {"line": 2}},
        "home": {"x": {"switch": "x-", "search_velocity": 10, "latch_velocity": 1, "backoff": 0, "max_travel": 300}}})")) ==
          "m.json:4:95: backoff 0 mm is impossible (allowed: > 0 and <= 10000 mm)");
}

TEST_CASE("gpio profile: spindle, its direction, mist and flood lines", "[host][gpio][machine]") {
    const MachineProfile p = parse_machine_profile(with_gpio(R"({
        "chip": "gpiochip0", "pen": {"line": 0},
        "spindle": {"line": 5}, "spindle_reverse": {"line": "vfd-rev", "active_low": true},
        "flood": {"line": 7, "bias": "pull-down"}})"),
                                                   "m.json");
    const GpioConfig& g = p.gpio;
    REQUIRE(g.present);
    CHECK(std::string(kMachineFunctionKeys[0]) == "spindle");
    CHECK(g.has_function[0]);
    CHECK(g.function[0].line == "5");
    CHECK(g.has_function[1]);
    CHECK(g.function[1].line == "vfd-rev");
    CHECK(g.function[1].active_low);
    CHECK_FALSE(g.has_function[2]);  // mist: not fitted
    CHECK(g.has_function[3]);
    CHECK(g.function[3].bias == "pull-down");
    CHECK(error_of(with_gpio(R"({"chip": "c", "mist": {"line": 70000}})")) ==
          "m.json:3:40: line offset must be 0..65535");
    CHECK(error_of(with_gpio(R"({"chip": "c", "flood": 3})")) ==
          "m.json:3:32: flood must be an object like {\"line\": 3}");
}

namespace {
// Line 3 of the document starts with `"output_coils": ` (16 columns) before the object.
std::string with_coils(const std::string& coils) {
    return pathstream::test::with_key("output_coils", coils);
}
}  // namespace

TEST_CASE("output coils profile: target and one coil per function", "[host][machine][coils]") {
    const MachineProfile none = parse_machine_profile(std::string("{") + kAxes + "}", "m.json");
    CHECK_FALSE(none.output_coils.present);
    const MachineProfile p = parse_machine_profile(
        with_coils(R"({"target": "modbus-tcp://10.0.0.7:502?unit=3", "spindle": 0,
                        "spindle_reverse": 1, "flood": 65535})"),
        "m.json");
    const OutputCoilsConfig& c = p.output_coils;
    REQUIRE(c.present);
    CHECK(c.target == "modbus-tcp://10.0.0.7:502?unit=3");
    CHECK(c.coil[0] == 0);
    CHECK(c.coil[1] == 1);
    CHECK(c.coil[2] == -1);  // mist: no coil
    CHECK(c.coil[3] == 65535);
    const MachineProfile rtu = parse_machine_profile(
        with_coils(
            R"({"target": "modbus-rtu:///dev/ttyUSB0?baud=9600&parity=E&unit=2", "mist": 4})"),
        "m.json");
    CHECK(rtu.output_coils.coil[2] == 4);
}

TEST_CASE("output coils profile: bad values are refused with the place and the reason",
          "[host][machine][coils]") {
    CHECK(error_of(with_coils("[]")) ==
          "m.json:3:17: output_coils must be an object like {\"target\": "
          "\"modbus-tcp://HOST:PORT?unit=1\", \"spindle\": 0}");
    CHECK(error_of(with_coils(R"({"spindle": 0})")) ==
          "m.json:3:17: output_coils has no \"target\"");
    CHECK(error_of(with_coils(R"({"target": 5, "spindle": 0})")) ==
          "m.json:3:28: target must be a Modbus URL string (modbus-tcp://HOST:PORT?unit=N or "
          "modbus-rtu://DEVICE?baud=B&unit=N)");
    CHECK(error_of(with_coils(R"({"target": "http://x", "spindle": 0})")) ==
          "m.json:3:28: bad target URL 'http://x': unknown scheme (want modbus-tcp:// or "
          "modbus-rtu://)");
    CHECK(error_of(with_coils(R"({"target": "modbus-rtu:///dev/ttyS0?unit=0", "spindle": 0})")) ==
          "m.json:3:28: unit 0 is the broadcast address: no answer would confirm a write (give "
          "the module's unit, 1..247)");
    CHECK(error_of(with_coils(R"({"target": "modbus-tcp://h:502"})")) ==
          "m.json:3:17: output_coils switches no function: give a coil for one or more of "
          "spindle, spindle_reverse, mist, flood");
    CHECK(error_of(with_coils(R"({"target": "modbus-tcp://h:502", "spindle": -1})")) ==
          "m.json:3:61: spindle coil address must be a whole number 0..65535");
    CHECK(error_of(with_coils(R"({"target": "modbus-tcp://h:502", "mist": 65536})")) ==
          "m.json:3:58: mist coil address must be a whole number 0..65535");
    CHECK(error_of(with_coils(R"({"target": "modbus-tcp://h:502", "flood": 2.5})")) ==
          "m.json:3:59: flood coil address must be a whole number 0..65535");
    CHECK(error_of(with_coils(R"({"target": "modbus-tcp://h:502", "spindle": 2, "flood": 2})")) ==
          "m.json:3:73: coil 2 is spindle's already: one coil per function");
    CHECK(error_of(with_coils(R"({"target": "modbus-tcp://h:502", "fan": 2})")) ==
          "m.json:3:57: unknown key \"fan\" (expected one of: flood, mist, spindle, "
          "spindle_reverse, target)");
}
