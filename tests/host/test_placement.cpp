// Placement (placement.hpp): each step's effect on the drawing's box, the documented order of
// the steps, fit into paper and work area, and the errors.
#include <catch2/catch.hpp>
#include <string>

#include "pathstream/host/placement.hpp"

using namespace pathstream::host;

namespace {

/// A 40 x 20 mm polyline rectangle at (10, 5).
Path rectangle() {
    Path p;
    p.subpaths.push_back(
        {PathBasis::kPolyline, true, {{10, 5}, {50, 5}, {50, 25}, {10, 25}}, 0, {}});
    return p;
}

Box2 box_of(const Path& p) {
    return *drawing_box(p);
}

}  // namespace

TEST_CASE("placement: nothing asked, nothing changed", "[placement]") {
    const Path p = rectangle();
    PlacementReport r;
    CHECK(place_path(p, {}, std::nullopt, &r).subpaths[0].points == p.subpaths[0].points);
    CHECK_FALSE(PlacementOptions{}.active());
}

TEST_CASE("placement: drawing box is the curve's, not the control points'", "[placement]") {
    Path p;
    p.subpaths.push_back({PathBasis::kBezier, false, {{0, 0}, {0, 10}, {10, 10}, {10, 0}}, 0, {}});
    const Box2 b = box_of(p);
    CHECK(b.y_max == Approx(7.5));
    CHECK(b.x_min == Approx(0));
    CHECK(b.x_max == Approx(10));
}

TEST_CASE("placement: rotate, flip, scale and translate", "[placement]") {
    PlacementOptions o;
    o.rotate = 90;
    Box2 b = box_of(place_path(rectangle(), o, std::nullopt));
    CHECK(b.x_min == Approx(-25));
    CHECK(b.x_max == Approx(-5));
    CHECK(b.y_min == Approx(10));
    CHECK(b.y_max == Approx(50));
    o = {};
    o.flip_y = true;
    o.scale = 2;
    o.translate = std::make_pair(1.0, 2.0);
    b = box_of(place_path(rectangle(), o, std::nullopt));
    CHECK(b.x_min == Approx(21));   // 10 * 2 + 1
    CHECK(b.y_min == Approx(-48));  // -25 * 2 + 2
    CHECK(b.y_max == Approx(-8));
}

TEST_CASE("placement: fit into a4 keeps the aspect and centres", "[placement]") {
    PlacementOptions o;
    o.fit = "a4";
    o.margin = 10;
    PlacementReport r;
    const Box2 b = box_of(place_path(rectangle(), o, std::nullopt, &r));
    CHECK(r.scale == Approx(190.0 / 40));
    CHECK(b.x_min == Approx(10));
    CHECK(b.x_max == Approx(200));
    CHECK((b.y_min + b.y_max) / 2 == Approx(148.5));
    CHECK(b.height() == Approx(95));
    CHECK(r.after->x_max == Approx(200));
}

TEST_CASE("placement: align top-left depends on the origin corner", "[placement]") {
    PlacementOptions o;
    o.fit = "a4-landscape";
    o.align = "top-left";
    o.rotate = 90;  // 20 x 40 after the turn: the height limits
    Box2 b = box_of(place_path(rectangle(), o, std::nullopt));
    CHECK(b.height() == Approx(210));
    CHECK(b.x_min == Approx(0));
    CHECK(b.y_min == Approx(0));  // top-left origin: y down, the top edge is y = 0
    o.origin = "bottom-left";
    b = box_of(place_path(rectangle(), o, std::nullopt));
    CHECK(b.y_max == Approx(210));  // y up: the top edge is y = 210
}

TEST_CASE("placement: fit area uses the work area, align without fit", "[placement]") {
    PlacementOptions o;
    o.fit = "area";
    const Box2 area{100, 0, 300, 200};
    const Box2 b = box_of(place_path(rectangle(), o, area));
    CHECK(b.x_min == Approx(100));
    CHECK(b.x_max == Approx(300));
    CHECK(b.y_min == Approx(50));
    o = {};
    o.align = "bottom-right";
    o.origin = "bottom-left";
    const Box2 c = box_of(place_path(rectangle(), o, std::nullopt));
    CHECK(c.x_max == Approx(0));
    CHECK(c.y_min == Approx(0));
    MachineProfile m;
    m.axes = {{"x", 1, 1, true, -5, 5}, {"y", 1, 1, true, 0, 3}};
    CHECK(work_area(m)->x_min == -5);
    m.axes[1].has_travel = false;
    CHECK_FALSE(work_area(m).has_value());
}

TEST_CASE("placement: bad values are refused with the option's name", "[placement]") {
    const Path p = rectangle();
    PlacementOptions o;
    o.fit = "area";
    CHECK_THROWS_WITH(place_path(p, o, std::nullopt),
                      Catch::Contains("--fit area needs a machine profile"));
    o.fit = "a9";
    CHECK_THROWS_WITH(place_path(p, o, std::nullopt), Catch::Contains("--fit: \"a9\""));
    o.fit = "a4";
    o.margin = 200;
    CHECK_THROWS_WITH(place_path(p, o, std::nullopt), Catch::Contains("--margin"));
    o = {};
    o.rotate = 45;
    CHECK_THROWS_WITH(place_path(p, o, std::nullopt), Catch::Contains("--rotate"));
    o = {};
    o.scale = 2;
    o.fit = "a4";
    CHECK_THROWS_WITH(place_path(p, o, std::nullopt), Catch::Contains("exclude"));
    o = {};
    o.align = "middle";
    CHECK_THROWS_WITH(place_path(p, o, std::nullopt), Catch::Contains("--align"));
    o = {};
    o.fit = "a4";
    CHECK_THROWS_AS(place_path(Path{}, o, std::nullopt), std::invalid_argument);
}

TEST_CASE("placement: a paper larger than the work area names the orientation that fits",
          "[placement]") {
    const std::optional<Box2> a3_landscape_area = Box2{0, 0, 430, 297};
    PlacementOptions o;
    o.fit = "a3";
    CHECK_THROWS_WITH(
        place_path(rectangle(), o, a3_landscape_area),
        Catch::Contains("--fit a3: the paper (297 x 420 mm) does not fit the machine's work area "
                        "(430 x 297 mm from (0, 0) mm); --fit a3-landscape does"));
    o.fit = "a2";
    CHECK_THROWS_WITH(place_path(rectangle(), o, a3_landscape_area),
                      Catch::Contains(", in either orientation"));
    o.fit = "a3-landscape";
    CHECK_NOTHROW(place_path(rectangle(), o, a3_landscape_area));
    CHECK_NOTHROW(place_path(rectangle(), o, std::nullopt));  // no machine: no check
}

TEST_CASE("placement: a fit keeps the edge clearance from the travel's edges", "[placement]") {
    const std::optional<Box2> area = Box2{0, 0, 430, 297};
    PlacementOptions o;
    o.fit = "area";
    o.edge_clearance = 0.006;
    const Box2 b = box_of(place_path(rectangle(), o, area));
    CHECK(b.x_min >= 0.006 - 1e-9);
    CHECK(b.y_min >= 0.006 - 1e-9);
    CHECK(b.x_max <= 430 - 0.006 + 1e-9);
    CHECK(b.y_max <= 297 - 0.006 + 1e-9);
    // A paper inside the area, away from its edges, is not changed by the clearance.
    o.fit = "a5";  // 148 x 210
    o.align = "center";
    PlacementOptions without = o;
    without.edge_clearance = 0;
    const std::optional<Box2> big = Box2{-10, -10, 430, 297};
    CHECK(box_of(place_path(rectangle(), o, big)).x_min ==
          box_of(place_path(rectangle(), without, big)).x_min);
}
