// The page's preview of a 3-axis router: x, y and z by name and the isometric view's facts,
// where a plotter's preview stays 2-D.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "serve/preview.hpp"

using namespace pathstream::host;
using namespace pathstream::host::serve;

namespace {

// Axes in an order other than x, y, z: the preview must take them by name.
MachineProfile router() {
    MachineProfile m;
    m.axes = {{"z", 100, 1000}, {"x", 250, 2000}, {"y", 250, 2000}};
    const double travel[3][2] = {{-60, 0}, {0, 600}, {0, 600}};
    for (int a = 0; a < 3; ++a) {
        m.axes[a].has_travel = true;
        m.axes[a].travel_min = travel[a][0];
        m.axes[a].travel_max = travel[a][1];
    }
    m.pen_down_delay = m.pen_up_delay = 0;
    return m;
}

// A pocket's outline: plunge at (100, 100), a square at z -12, retract; a rapid to a slot.
// Points are in the machine's axis order: z, x, y.
Path pocket() {
    Path path;
    path.axes = 3;
    Subpath square;
    square.basis = PathBasis::kPolyline;
    square.points = {{-5, 100, 100},  {-12, 100, 100}, {-12, 140, 100}, {-12, 140, 140},
                     {-12, 100, 140}, {-12, 100, 100}, {-5, 100, 100}};
    Subpath slot;
    slot.basis = PathBasis::kPolyline;
    slot.points = {{-5, 200, 100}, {-12, 240, 100}, {-5, 200, 100.5}};
    path.subpaths = {square, slot};
    return path;
}

}  // namespace

TEST_CASE("serve: a router's preview has x, y, z by name and the isometric view", "[serve]") {
    const MachineProfile m = router();
    const Path path = pocket();
    const Plan plan = plan_path(to_bezier_segments(path), m);
    const nlohmann::ordered_json p = preview_json(plan, path, m);
    REQUIRE(p.contains("view"));
    CHECK(p["view"]["projection"] == "isometric");
    CHECK(p["view"]["axes"] == nlohmann::ordered_json::array({1, 2, 0}));
    CHECK(p["view"]["box"]["z_min"] == -60);
    CHECK(p["view"]["box"]["x_max"] == 600);
    const auto& x = p["path"]["x"];
    const auto& y = p["path"]["y"];
    const auto& z = p["path"]["z"];
    const auto& pen = p["path"]["pen"];
    REQUIRE(z.size() == x.size());
    REQUIRE(y.size() == x.size());
    // The plunge and the retract are kept: a vertex at the square's corner at -5 and at -12.
    const auto has = [&](double vx, double vy, double vz) {
        for (std::size_t i = 0; i < x.size(); ++i) {
            if (std::fabs(x[i].get<double>() - vx) < 1e-3 &&
                std::fabs(y[i].get<double>() - vy) < 1e-3 &&
                std::fabs(z[i].get<double>() - vz) < 1e-3)
                return true;
        }
        return false;
    };
    CHECK(has(100, 100, -5));
    CHECK(has(100, 100, -12));
    CHECK(has(140, 140, -12));
    CHECK(has(240, 100, -12));
    CHECK(std::count(pen.begin(), pen.end(), 0) >= 1);  // the rapid between them
    // Straight runs merge in 3-D: the square's four sides, not its many spans.
    CHECK(x.size() * 5 < plan.spans.size());
    // Speeds over all three axes: the plunge moves z alone and still has a speed.
    const auto& v = p["speed"]["v"];
    CHECK(*std::max_element(v.begin(), v.end()) > 0);
    CHECK(*std::max_element(v.begin(), v.end()) <= m.travel_feed + 1e-6);

    // The streamed plan's preview is the whole plan's.
    PreviewRecorder recorder(path, m);
    for (const CoreSpan& s : plan.spans) recorder.span(s);
    const nlohmann::ordered_json streamed = recorder.finish(
        plan.duration, plan.total_ticks, plan.pen.size(), plan.path_length, plan.travel_length);
    CHECK(streamed["path"] == p["path"]);
    CHECK(streamed["view"] == p["view"]);
}

TEST_CASE("serve: a plotter's preview has no z and no view", "[serve]") {
    MachineProfile m;
    m.axes = {{"x", 250, 3000}, {"y", 250, 3000}};
    Path path;
    Subpath line;
    line.basis = PathBasis::kPolyline;
    line.points = {{10, 10}, {110, 10}, {110, 60}};
    path.subpaths = {line};
    const nlohmann::ordered_json p = preview_json(plan_path(to_bezier_segments(path), m), path, m);
    CHECK_FALSE(p.contains("view"));
    CHECK_FALSE(p["path"].contains("z"));
    // A third axis not named z: still the plotter's view.
    m.axes.push_back({"a", 100, 1000});
    path.axes = 3;
    line.points = {{10, 10, 0}, {110, 10, 0}, {110, 60, 0}};
    path.subpaths = {line};
    const nlohmann::ordered_json a = preview_json(plan_path(to_bezier_segments(path), m), path, m);
    CHECK_FALSE(a.contains("view"));
    CHECK_FALSE(a["path"].contains("z"));
}
