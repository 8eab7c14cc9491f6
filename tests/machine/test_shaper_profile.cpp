// The profile's "input_shaper" object: a shaper per axis by name, checked against the device's
// history at the profile's tick rate, errors with their place.
#include <catch2/catch.hpp>
#include <string>

#include "pathstream/machine/machine.hpp"
#include "profile_text.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {
using test::kTwoAxes;
// Line 3 of the document starts with `"input_shaper": ` (16 columns) before the object.
std::string with_shaper(const std::string& shaper) {
    return test::with_key("input_shaper", shaper);
}
std::string error_of(const std::string& text) {
    return test::profile_error(text);
}
}  // namespace

TEST_CASE("shaper profile: one shaper per named axis", "[host][machine][shaper]") {
    const MachineProfile none = parse_machine_profile(std::string("{") + kTwoAxes + "}", "m.json");
    REQUIRE(none.input_shaper.size() == 2);
    CHECK_FALSE(none.input_shaper[0]);
    const MachineProfile p = parse_machine_profile(
        with_shaper(R"({"y": {"type": "ei", "frequency": 38.5, "damping": 0.05}})"), "m.json");
    REQUIRE(p.input_shaper.size() == 2);
    CHECK_FALSE(p.input_shaper[0]);
    REQUIRE(p.input_shaper[1]);
    CHECK(p.input_shaper[1]->type == ShaperType::kEi);
    CHECK(p.input_shaper[1]->frequency_hz == 38.5);
    CHECK(p.input_shaper[1]->damping == 0.05);
    const MachineProfile d =
        parse_machine_profile(with_shaper(R"({"x": {"type": "mzv", "frequency": 40}})"), "m.json");
    CHECK(d.input_shaper[0]->damping == 0.1);  // the default damping ratio
}

TEST_CASE("shaper profile: bad values are refused with the place and the reason",
          "[host][machine][shaper]") {
    CHECK(error_of(with_shaper("[]")) ==
          "m.json:3:17: input_shaper must be an object like {\"x\": {\"type\": \"mzv\", "
          "\"frequency\": 40}}");
    CHECK(error_of(with_shaper(R"({"z": {"type": "zv", "frequency": 40}})")) ==
          "m.json:3:23: the profile has no axis \"z\"");
    CHECK(error_of(with_shaper(R"({"x": {"type": "fir", "frequency": 40}})")) ==
          "m.json:3:32: unknown shaper type \"fir\" (known: zv, zvd, mzv, ei, 2hump_ei, "
          "3hump_ei)");
    CHECK(error_of(with_shaper(R"({"x": {"type": "zv"}})")) ==
          "m.json:3:23: the shaper needs a \"frequency\" in Hz");
    CHECK(error_of(with_shaper(R"({"x": {"type": "zv", "frequency": 40, "q": 1}})"))
              .find("unknown key \"q\"") != std::string::npos);
    // 1 kHz ticks: a ZV shaper at 400 Hz lasts 1.25 ticks.
    CHECK(error_of(with_shaper(R"({"x": {"type": "zv", "frequency": 400}})")) ==
          "m.json:3:51: zv shaper at 400 Hz lasts 1.2563 ticks at 1000 Hz: at least 2 are needed "
          "(a lower frequency or a faster tick)");
    CHECK(error_of(with_shaper(R"({"x": {"type": "3hump_ei", "frequency": 0.3}})"))
              .find("the device remembers 4095") != std::string::npos);
    CHECK(error_of(with_shaper(R"({"x": {"type": "ei", "frequency": 40, "damping": 1}})"))
              .find("damping 1") != std::string::npos);
}

TEST_CASE("shaper profile: plan_for_shaper is a boolean and needs a shaper",
          "[host][machine][shaper]") {
    const MachineProfile p = parse_machine_profile(
        std::string("{") + kTwoAxes +
            ",\n\"input_shaper\": {\"x\": {\"type\": \"zv\", \"frequency\": 40}},\n"
            "\"plan_for_shaper\": true}",
        "m.json");
    CHECK(p.plan_for_shaper);
    CHECK(error_of(std::string("{") + kTwoAxes + ",\n\"plan_for_shaper\": true}") ==
          "m.json:3:20: plan_for_shaper needs an \"input_shaper\" to plan for");
    CHECK(error_of(std::string("{") + kTwoAxes + ",\n\"plan_for_shaper\": 1}") ==
          "m.json:3:20: plan_for_shaper must be true or false");
}
