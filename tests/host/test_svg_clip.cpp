// clip-path and nested viewports cut the strokes at the clip's boundary: hatches clipped to a
// rectangle and a circle end exactly there, and a clip that cannot be applied says so.
#include <catch2/catch.hpp>
#include <chrono>
#include <cmath>
#include <string>
#include <vector>

#include "pathstream/host/svg_clip.hpp"
#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;
using svg::Point;

namespace {

// A 100 x 100 mm document whose user unit is one millimetre.
std::string doc(const std::string& body) {
    return R"~(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">)~" +
           body + "</svg>";
}

Path read(const std::string& body, svg::SvgReadInfo* info = nullptr) {
    return parse_svg_path(doc(body), "t.svg", 0.01, info);
}

// Horizontal lines from x = 0 to 100 at y = 5, 15, ..., 95.
std::string hatch() {
    std::string s;
    for (int y = 5; y < 100; y += 10) {
        s += "<line x1=\"0\" y1=\"" + std::to_string(y) + "\" x2=\"100\" y2=\"" +
             std::to_string(y) + "\"/>";
    }
    return s;
}

double length(const Path& p) {
    double sum = 0;
    for (const Subpath& s : p.subpaths) {
        for (std::size_t i = 1; i < s.points.size(); ++i)
            sum += std::hypot(s.points[i][0] - s.points[i - 1][0],
                              s.points[i][1] - s.points[i - 1][1]);
    }
    return sum;
}

Point start(const Subpath& s) {
    return {s.points.front()[0], s.points.front()[1]};
}
Point end(const Subpath& s) {
    return {s.points.back()[0], s.points.back()[1]};
}

}  // namespace

TEST_CASE("svg clip: a hatch clipped to a rect ends at its sides", "[svg][clip]") {
    const std::string clip =
        R"~(<defs><clipPath id="c"><rect x="20" y="30" width="40" height="20"/></clipPath></defs>)~";
    const Path whole = read(hatch() + R"~(<line x1="0" y1="0" x2="100" y2="100"/>)~");
    const Path p = read(clip + "<g clip-path=\"url(#c)\">" + hatch() +
                        R"~(<line x1="0" y1="0" x2="100" y2="100"/></g>)~");
    CHECK(length(whole) == Approx(1000 + 100 * std::sqrt(2.0)));
    REQUIRE(p.subpaths.size() == 3);
    for (const Subpath& s : p.subpaths) CHECK(s.basis == PathBasis::kPolyline);
    CHECK(start(p.subpaths[0]).x == Approx(20).margin(1e-9));
    CHECK(end(p.subpaths[0]).x == Approx(60).margin(1e-9));
    CHECK(start(p.subpaths[0]).y == Approx(35).margin(1e-9));
    CHECK(start(p.subpaths[1]).y == Approx(45).margin(1e-9));
    // the diagonal enters at the top side (30, 30) and leaves at the bottom (50, 50)
    CHECK(start(p.subpaths[2]).x == Approx(30).margin(1e-9));
    CHECK(start(p.subpaths[2]).y == Approx(30).margin(1e-9));
    CHECK(end(p.subpaths[2]).x == Approx(50).margin(1e-9));
    CHECK(end(p.subpaths[2]).y == Approx(50).margin(1e-9));
    CHECK(length(p) == Approx(80 + 20 * std::sqrt(2.0)));
}

TEST_CASE("svg clip: a hatch clipped to a circle ends on it within the tolerance", "[svg][clip]") {
    const Path p = read(R"~(<clipPath id="c"><circle cx="50" cy="50" r="20"/></clipPath>
        <g clip-path="url(#c)">)~" +
                        hatch() + "</g>");
    REQUIRE(p.subpaths.size() == 4);  // y = 35, 45, 55, 65
    for (const Subpath& s : p.subpaths) {
        REQUIRE(s.points.size() == 2);
        const double dy = start(s).y - 50;
        const double half = std::sqrt(400 - dy * dy);
        // the circle is flattened within 0.01 mm, and a line meets it at a slant
        const double slack = 0.01 * 20 / half + 1e-9;
        CHECK(start(s).x == Approx(50 - half).margin(slack));
        CHECK(end(s).x == Approx(50 + half).margin(slack));
        CHECK(start(s).x >= 50 - half - 1e-9);  // the chords lie inside the circle
    }
}

TEST_CASE("svg clip: clip-rule, units, the clip's transform and curves", "[svg][clip]") {
    const std::string rings =
        R"~(<circle cx="50" cy="50" r="30"/><circle cx="50" cy="50" r="10"/>)~";
    const std::string line = R"~(<line x1="0" y1="50" x2="100" y2="50"/>)~";
    // two shapes are a union whatever the rule; one path of two rings follows its rule
    const std::string d =
        "M 20 50 A 30 30 0 1 0 80 50 A 30 30 0 1 0 20 50 Z "
        "M 40 50 A 10 10 0 1 0 60 50 A 10 10 0 1 0 40 50 Z";
    CHECK(
        read("<clipPath id=\"c\">" + rings + "</clipPath><g clip-path=\"url(#c)\">" + line + "</g>")
            .subpaths.size() == 1);
    CHECK(read("<clipPath id=\"c\"><path clip-rule=\"evenodd\" d=\"" + d +
               "\"/></clipPath><g clip-path=\"url(#c)\">" + line + "</g>")
              .subpaths.size() == 2);
    CHECK(read("<clipPath id=\"c\" style=\"clip-rule:evenodd\"><path d=\"" + d +
               "\"/></clipPath><g clip-path=\"url(#c)\">" + line + "</g>")
              .subpaths.size() == 2);
    // objectBoundingBox: the left half of the hatch's box (0..100)
    const Path box = read(R"~(<clipPath id="c" clipPathUnits="objectBoundingBox">
        <rect y="-0.1" width="0.5" height="1.2"/></clipPath><g clip-path="url(#c)">)~" +
                          hatch() + "</g>");
    REQUIRE(box.subpaths.size() == 10);
    CHECK(end(box.subpaths[0]).x == Approx(50).margin(1e-9));
    // the clipPath's transform, and the element's own transform moving its clip along
    const Path moved =
        read(R"~(<clipPath id="c" transform="translate(10 0)"><rect width="20" height="100"/>
        </clipPath><line x1="0" y1="5" x2="100" y2="5" clip-path="url(#c)" transform="translate(0 10)"/>)~");
    REQUIRE(moved.subpaths.size() == 1);
    CHECK(start(moved.subpaths[0]).x == Approx(10).margin(1e-9));
    CHECK(end(moved.subpaths[0]).x == Approx(30).margin(1e-9));
    CHECK(end(moved.subpaths[0]).y == Approx(15).margin(1e-9));
    // a circle cut in half stays on the circle; one wholly inside keeps its Bezier pieces
    const Path half = read(R"~(<clipPath id="c"><rect width="50" height="100"/></clipPath>
        <circle cx="50" cy="50" r="20" clip-path="url(#c)"/><circle cx="20" cy="20" r="5" clip-path="url(#c)"/>)~");
    REQUIRE(half.subpaths.size() == 2);
    const Subpath& cut = half.subpaths[0];
    for (std::size_t i = 0; i < cut.points.size(); i += cut.basis == PathBasis::kBezier ? 3 : 1) {
        const PathPoint q = cut.points[i];  // the ends of pieces lie on the circle
        CHECK(q[0] <= 50 + 1e-9);
        CHECK(std::hypot(q[0] - 50, q[1] - 50) == Approx(20).margin(0.011));
    }
    CHECK(half.subpaths[1].basis == PathBasis::kBezier);
    CHECK(half.subpaths[1].points.size() == 13);
}

TEST_CASE("svg clip: nested svg and symbol viewports cut what lies outside", "[svg][clip]") {
    const std::string line = R"~(<line x1="-10" y1="10" x2="40" y2="10"/>)~";
    const Path p = read("<svg x=\"10\" y=\"10\" width=\"20\" height=\"20\">" + line + "</svg>");
    REQUIRE(p.subpaths.size() == 1);
    CHECK(start(p.subpaths[0]).x == Approx(10).margin(1e-9));
    CHECK(end(p.subpaths[0]).x == Approx(30).margin(1e-9));
    CHECK(end(p.subpaths[0]).y == Approx(20).margin(1e-9));
    for (const char* overflow : {"visible", "auto"}) {
        const Path v = read("<svg x=\"10\" y=\"10\" width=\"20\" height=\"20\" overflow=\"" +
                            std::string(overflow) + "\">" + line + "</svg>");
        CHECK(start(v.subpaths.at(0)).x == Approx(0).margin(1e-9));
        CHECK(end(v.subpaths.at(0)).x == Approx(50).margin(1e-9));
    }
    // the viewport, not the viewBox: meet leaves room beside the viewBox that still shows
    const Path meet = read(R"~(<svg width="40" height="20" viewBox="0 0 10 10">
        <line x1="-100" y1="5" x2="100" y2="5"/></svg>)~");
    CHECK(start(meet.subpaths.at(0)).x == Approx(0).margin(1e-9));
    CHECK(end(meet.subpaths.at(0)).x == Approx(40).margin(1e-9));
    const Path symbol =
        read(R"~(<defs><symbol id="s" viewBox="0 0 10 10"><line x1="-5" y1="5" x2="15" y2="5"/>
        </symbol></defs><use href="#s" x="10" y="10" width="20" height="20"/>)~");
    CHECK(start(symbol.subpaths.at(0)).x == Approx(10).margin(1e-9));
    CHECK(end(symbol.subpaths.at(0)).x == Approx(30).margin(1e-9));
}

TEST_CASE("svg clip: clips that cannot be applied warn and draw the content whole", "[svg][clip]") {
    const auto warnings_of = [](const std::string& body, std::size_t subpaths) {
        svg::SvgReadInfo info;
        const Path p = read(body, &info);
        CHECK(p.subpaths.size() == subpaths);
        CHECK(length(p) == Approx(100.0 * static_cast<double>(subpaths)));
        return info.warnings;
    };
    CHECK(warnings_of(R"~(<line x2="100" y1="1" y2="1" clip-path="url(#nothing)"/>)~", 1) ==
          std::vector<std::string>{
              "t.svg:1:121: clip-path refers to #nothing, which does not exist; drawn unclipped"});
    CHECK(warnings_of(R"~(<clipPath id="c"><text>A</text></clipPath>
<line x2="100" y1="1" y2="1" clip-path="url(#c)"/>)~",
                      1) ==
          std::vector<std::string>{"t.svg:2:30: clip-path #c holds a <text>, which the reader "
                                   "cannot clip to; drawn unclipped"});
    CHECK(warnings_of(
              R"~(<clipPath id="c" clip-path="url(#c)"><rect width="50" height="50"/></clipPath>
<line x2="100" y1="1" y2="1" clip-path="url(#c)"/>)~",
              1) == std::vector<std::string>{"t.svg:2:30: clip-path #c refers to itself (circular "
                                             "reference); drawn unclipped"});
    CHECK(warnings_of(
              R"~(<clipPath id="a" clip-path="url(#b)"><rect width="50" height="50"/></clipPath>
<clipPath id="b" clip-path="url(#a)"><rect width="50" height="50"/></clipPath>
<line x2="100" y1="1" y2="1" clip-path="url(#a)"/>)~",
              1) == std::vector<std::string>{"t.svg:3:30: clip-path #a refers to itself (circular "
                                             "reference); drawn unclipped"});
    CHECK(warnings_of(R"~(<line x2="100" y1="1" y2="1" style="clip-path: circle(5px)"/>)~", 1)
              .at(0) ==
          "t.svg:1:128: clip-path 'circle(5px)' is not a url(#id) (not supported); "
          "drawn unclipped");
    // a chain of clipPaths each clipped by the next: applied up to a depth, then refused
    std::string chain;
    for (int i = 0; i < 40; ++i) {
        chain += "<clipPath id=\"k" + std::to_string(i) + "\" clip-path=\"url(#k" +
                 std::to_string(i + 1) + ")\"><rect width=\"100\" height=\"100\"/></clipPath>";
    }
    CHECK_THAT(
        warnings_of(chain + R"~(<line x2="100" y1="1" y2="1" clip-path="url(#k0)"/>)~", 1).at(0),
        Catch::Matchers::Contains("clip paths clipped more than 16 deep"));
}

TEST_CASE("svg clip: a huge hatch against a fine clip costs bounded time", "[svg][clip]") {
    // 20,000 diagonal lines across a clip of 2,000 tiny teeth
    std::string teeth = "M 0 50";
    for (int i = 0; i < 1000; ++i) {
        teeth += " L " + std::to_string(i * 0.1 + 0.05) + " 0 L " + std::to_string(i * 0.1 + 0.1) +
                 " 50";
    }
    std::string lines;
    for (int i = 0; i < 20000; ++i) {
        const double x = i * 0.005;
        lines += "<line x1=\"" + std::to_string(x) + "\" y1=\"0\" x2=\"" + std::to_string(x + 1) +
                 "\" y2=\"50\"/>";
    }
    const auto t0 = std::chrono::steady_clock::now();
    svg::SvgReadInfo info;
    const Path p = read("<clipPath id=\"c\"><path d=\"" + teeth +
                            " Z\"/></clipPath><g clip-path=\"url(#c)\">" + lines + "</g>",
                        &info);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    CHECK(p.subpaths.size() > 20000);
    CHECK(seconds < 20);  // about 1 s unindexed would be 40 M edge tests; the grid does far less
    WARN("20,000 lines against 2,000 teeth: " << p.subpaths.size() << " pieces in " << seconds
                                              << " s");
}

TEST_CASE("svg clip: ClipRegion cuts a segment at every crossing", "[svg][clip]") {
    svg::ClipShape square;
    square.rings.push_back({{0, 0}, {10, 0}, {10, 10}, {0, 10}});
    const svg::ClipRegion region({square});
    CHECK(region.contains({5, 5}));
    CHECK_FALSE(region.contains({15, 5}));
    std::vector<svg::ClipRegion::Crossing> hits;
    region.crossings({-10, 5}, {30, 5}, hits);
    REQUIRE(hits.size() == 2);
    CHECK(hits[0].t == Approx(0.25));
    CHECK(hits[1].t == Approx(0.5));
    CHECK(hits[0].delta == -hits[1].delta);
    // through a vertex: one crossing, not two
    region.crossings({-5, -5}, {5, 5}, hits);
    CHECK(hits.size() == 1);
    region.crossings({20, 5}, {30, 5}, hits);
    CHECK(hits.empty());
}
