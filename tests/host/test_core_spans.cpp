// Path -> core spans: clamped open ends, exact joints, straight pen-up travel, range errors.
#include <catch2/catch.hpp>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

TEST_CASE("open B-spline and Catmull-Rom start and end at their first and last points",
          "[host][spans]") {
    for (const char* basis : {"bspline", "catmull-rom"}) {
        const Path p =
            parse_json_path(std::string(R"({"basis": ")") + basis +
                                R"(", "points": [[0, 0], [10, 3], [20, -4], [30, 1.5]]})",
                            "t.json");
        const auto spans = uniform_core_spans(p, "t.json", 0.001, 16);
        REQUIRE(spans.size() == 3);
        CHECK(core_value_at(spans.front(), 0, 0) == 0);
        CHECK(core_value_at(spans.front(), 1, 0) == 0);
        CHECK(core_value_at(spans.back(), 0, 16) == 30000);
        CHECK(core_value_at(spans.back(), 1, 16) == 1500);
        for (std::size_t i = 1; i < spans.size(); ++i) {  // no gap at any joint
            for (std::size_t a = 0; a < 2; ++a) {
                CHECK(core_value_at(spans[i - 1], a, 16) == core_value_at(spans[i], a, 0));
            }
        }
    }
}

TEST_CASE("polyline segments are exactly straight and travel joins subpaths pen-up",
          "[host][spans]") {
    const Path p = parse_json_path(R"({"subpaths": [
        {"basis": "polyline", "points": [[0, 0], [3, 0]]},
        {"basis": "polyline", "points": [[3, 3], [0, 3]]}]})",
                                   "t.json");
    const auto spans = uniform_core_spans(p, "t.json", 0.001, 3);
    REQUIRE(spans.size() == 3);
    CHECK(spans[0].pen_down);
    CHECK_FALSE(spans[1].pen_down);
    CHECK(spans[2].pen_down);
    for (std::uint32_t k = 0; k <= 3; ++k) {
        CHECK(core_value_at(spans[0], 0, k) == static_cast<int>(1000 * k));  // exactly linear
        CHECK(core_value_at(spans[1], 0, k) == 3000);                        // travel: x fixed
        CHECK(core_value_at(spans[1], 1, k) == static_cast<int>(1000 * k));  // y 0 -> 3 mm
    }
}

TEST_CASE("points beyond the core's range are rejected with the subpath's location",
          "[host][spans]") {
    const Path p = parse_json_path("{\"points\": [[0, 0], [200000, 0]]}", "t.json");
    try {
        (void)uniform_core_spans(p, "t.json", 0.001, 8);
        FAIL("expected an InputError");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()).rfind("t.json:1:12: subpath 0: axis 0 value ", 0) == 0);
        CHECK(std::string(e.what()).find("outside the core's range") != std::string::npos);
    }
    CHECK_NOTHROW(uniform_core_spans(p, "t.json", 0.01, 8));
}
