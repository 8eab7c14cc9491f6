// The machine profile's "resonance" object: modes per axis name for the simulator, each bad
// value with its file:line:col; and sim's --mode option merged with it.
#include <catch2/catch.hpp>
#include <stdexcept>
#include <string>

#include "mode_option.hpp"
#include "pathstream/machine/machine.hpp"
#include "profile_text.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

using test::kTwoAxes;

// Line 3 of the document starts with `"resonance": ` (13 columns) before the object.
std::string with_resonance(const std::string& resonance) {
    return test::with_key("resonance", resonance);
}

std::string error_of(const std::string& text) {
    return test::profile_error(text);
}

std::string mode_error(const std::vector<std::string>& options, const MachineProfile& p) {
    try {
        run_modes(options, p);
    } catch (const std::invalid_argument& e) {
        return e.what();
    }
    return "no error";
}

}  // namespace

TEST_CASE("resonance profile: modes by axis name, in axis order", "[machine][resonance]") {
    const MachineProfile none = parse_machine_profile(std::string("{") + kTwoAxes + "}", "m.json");
    CHECK(none.resonance.empty());
    const MachineProfile p =
        parse_machine_profile(with_resonance(R"({"y": [{"frequency": 40, "damping": 0.05},
                                 {"frequency": 120.5, "damping": 1}]})"),
                              "m.json");
    REQUIRE(p.resonance.size() == 2);
    CHECK(p.resonance[0].empty());
    REQUIRE(p.resonance[1].size() == 2);
    CHECK(p.resonance[1][0].frequency_hz == 40);
    CHECK(p.resonance[1][0].damping == 0.05);
    CHECK(p.resonance[1][1].frequency_hz == 120.5);
    CHECK(p.resonance[1][1].damping == 1);
}

TEST_CASE("resonance profile: bad values name their place", "[machine][resonance]") {
    CHECK(error_of(with_resonance("[]")) ==
          "m.json:3:14: resonance must be an object like {\"x\": [{\"frequency\": 40, "
          "\"damping\": 0.05}]}");
    CHECK(error_of(with_resonance(R"({"z": []})")).rfind("m.json:3:", 0) == 0);
    CHECK(error_of(with_resonance(R"({"z": []})")).find("\"z\"") != std::string::npos);
    CHECK(error_of(with_resonance(R"({"x": []})")) ==
          "m.json:3:20: axis x's resonance must be an array of 1 to 4 modes like "
          "[{\"frequency\": 40, \"damping\": 0.05}]");
    CHECK(error_of(with_resonance(R"({"x": [{"frequency": 40}]})")) ==
          "m.json:3:21: mode has no \"damping\"");
    CHECK(error_of(with_resonance(R"({"x": [{"frequency": 40, "damping": 0.05, "q": 1}]})"))
              .rfind("m.json:3:", 0) == 0);
    CHECK(error_of(with_resonance(R"({"x": [{"frequency": 0, "damping": 0.05}]})")) ==
          "m.json:3:35: frequency 0 Hz is impossible (allowed: > 0 and <= 1e+06 Hz)");
    CHECK(error_of(with_resonance(R"({"x": [{"frequency": 500, "damping": 0.05}]})")) ==
          "m.json:3:35: frequency 500 Hz is impossible (allowed: > 0 and below half the tick "
          "rate, 500 Hz)");
    CHECK(error_of(with_resonance(R"({"x": [{"frequency": 40, "damping": 1.5}]})")) ==
          "m.json:3:50: damping 1.5 (ratio) is impossible (allowed: > 0 and <= 1 (ratio))");
    CHECK(error_of(with_resonance(R"({"x": [{"frequency": "40", "damping": 0.1}]})")) ==
          "m.json:3:35: frequency must be a number");
}

TEST_CASE("sim --mode: AXIS:FREQ_HZ:DAMPING, errors name the bad part", "[host][resonance]") {
    const ModeOption o = parse_mode_option("y:40.5:0.05");
    CHECK(o.axis == "y");
    CHECK(o.mode.frequency_hz == 40.5);
    CHECK(o.mode.damping == 0.05);
    const auto error = [](const std::string& text) {
        try {
            parse_mode_option(text);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error("x:40") == "--mode x:40: expected AXIS:FREQ_HZ:DAMPING, e.g. x:40:0.05");
    CHECK(error("x:40:0.1:2") ==
          "--mode x:40:0.1:2: expected AXIS:FREQ_HZ:DAMPING, e.g. x:40:0.05");
    CHECK(error(":40:0.1") == "--mode :40:0.1: the axis name is empty");
    CHECK(error("x:forty:0.1") == "--mode x:forty:0.1: frequency \"forty\" is not a number");
    CHECK(error("x:40Hz:0.1") == "--mode x:40Hz:0.1: frequency \"40Hz\" is not a number");
    CHECK(error("x:-4:0.1") == "--mode x:-4:0.1: frequency -4 Hz is impossible (allowed: > 0)");
    CHECK(error("x:40:") == "--mode x:40:: damping \"\" is not a number");
    CHECK(error("x:40:0") == "--mode x:40:0: damping 0 is impossible (allowed: > 0 and <= 1)");
    CHECK(error("x:inf:0.1") == "--mode x:inf:0.1: frequency \"inf\" is not a number");
}

TEST_CASE("sim --mode replaces the profile's modes of its axis", "[host][resonance]") {
    const MachineProfile p =
        parse_machine_profile(with_resonance(R"({"x": [{"frequency": 40, "damping": 0.05}],
                           "y": [{"frequency": 60, "damping": 0.1}]})"),
                              "m.json");
    const auto profile_only = run_modes({}, p);
    REQUIRE(profile_only.size() == 2);
    CHECK(profile_only[0].size() == 1);
    const auto merged = run_modes({"y:30:0.02", "y:90:0.2"}, p);
    REQUIRE(merged.size() == 2);
    REQUIRE(merged[0].size() == 1);
    CHECK(merged[0][0].frequency_hz == 40);
    REQUIRE(merged[1].size() == 2);
    CHECK(merged[1][0].frequency_hz == 30);
    CHECK(merged[1][1].damping == 0.2);
    CHECK(describe_modes(merged, p) == "x: 40 Hz zeta 0.05; y: 30 Hz zeta 0.02, 90 Hz zeta 0.2");
    const MachineProfile bare = parse_machine_profile(std::string("{") + kTwoAxes + "}", "m.json");
    CHECK(run_modes({}, bare).empty());
    CHECK(mode_error({"q:40:0.1"}, bare) ==
          "--mode q:40:0.1: axis \"q\" is not in the machine profile (axes: x, y)");
    CHECK(mode_error({"x:600:0.1"}, bare) ==
          "--mode x:600:0.1: mode frequency 600 Hz is impossible (allowed: > 0 and below half "
          "the tick rate, 500 Hz)");
    CHECK(mode_error({"x:10:0.1", "x:20:0.1", "x:30:0.1", "x:40:0.1", "x:50:0.1"}, bare) ==
          "--mode x:50:0.1: axis x has 4 modes already (the most an axis may have)");
}
