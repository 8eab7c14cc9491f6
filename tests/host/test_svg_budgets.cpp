// Hostile SVGs cost bounded work: deep nesting, <use> copies that multiply geometry, and
// copies of nothing each end in a clean error at the element, never a crash or a long run.
#include <catch2/catch.hpp>
#include <string>

#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

// The reader's message for `text`, or "" when it reads.
std::string error_of(const std::string& text) {
    try {
        parse_svg_path(text, "h.svg");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

// `levels` groups of `fan` <use>s of the level below, the lowest using `bottom`.
std::string fan_out(const std::string& bottom_defs, const std::string& bottom_id, int levels,
                    int fan) {
    std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\"><defs>" + bottom_defs;
    std::string below = bottom_id;
    for (int l = 1; l <= levels; ++l) {
        s += "<g id=\"l" + std::to_string(l) + "\">";
        for (int i = 0; i < fan; ++i) s += "<use href=\"#" + below + "\"/>";
        s += "</g>";
        below = "l" + std::to_string(l);
    }
    return s + "</defs><use href=\"#" + below + "\"/><path d=\"M0 0 L1 1\"/></svg>";
}

}  // namespace

TEST_CASE("svg budgets: nesting deeper than 500 elements is refused at the element",
          "[svg][budgets]") {
    const auto nested = [](int n) {
        std::string s = "<svg xmlns=\"http://www.w3.org/2000/svg\">";
        for (int i = 0; i < n; ++i) s += "<g>\n";
        s += "<path d=\"M0 0 L1 1\"/>";
        for (int i = 0; i < n; ++i) s += "</g>";
        return s + "</svg>";
    };
    CHECK(error_of(nested(498)).empty());
    CHECK(error_of(nested(10000)) ==
          "h.svg:501:1: elements nested more than 500 deep (the reader's limit)");
}

TEST_CASE("svg budgets: <use> copies are counted in the geometry they expand to",
          "[svg][budgets]") {
    std::string d = "M0 0";
    for (int i = 0; i < 1000; ++i)
        d += " L" + std::to_string(i % 50) + " " + std::to_string(i / 50);
    const std::string path = "<path id=\"p\" d=\"" + d + "\"/>";
    // 10^2 copies of 1000 segments: 100,000 pieces, within the budget for this file's size.
    CHECK(error_of(fan_out(path, "p", 2, 10)).empty());
    // 10^4 copies: 10^7 pieces, refused once the budget (250,000 + 16 per byte) is spent.
    const std::string big = fan_out(path, "p", 4, 10);
    const std::string budget = std::to_string(250000 + 16 * big.size());
    CHECK_THAT(error_of(big),
               Catch::Contains("the drawing expands to more than " + budget + " curve pieces"));
}

TEST_CASE("svg budgets: copies of nothing count as copies", "[svg][budgets]") {
    const std::string missing = fan_out("<g id=\"m\"><use href=\"#nothing\"/></g>", "m", 6, 10);
    CHECK_THAT(error_of(missing), Catch::Contains("too many <use> copies (more than 100000)"));
}
