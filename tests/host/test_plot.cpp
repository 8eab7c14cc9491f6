// Plots and the report: well-formed SVG with the expected series, decimation that keeps peaks,
// differentiation, PNG conversion without a shell, the report's figures; and a simulated
// drawing end to end (set PATHSTREAM_PLOT_DIR to keep its plots and report for a look).
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <pugixml.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "pathstream/host/plan.hpp"
#include "pathstream/host/plot.hpp"
#include "pathstream/sim/device.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "sim_plots.hpp"

using namespace pathstream;
using namespace pathstream::host;
namespace fs = std::filesystem;

namespace {

MachineProfile profile_xy() {
    MachineProfile m;
    m.axes = {{"x", 120.0, 2000.0}, {"y", 100.0, 1500.0}};
    m.mm_per_lsb = 0.001;
    m.tick_hz = 1000;
    m.feed = 50;
    m.travel_feed = 90;
    return m;
}

BezierSegment straight(PathPoint a, PathPoint b, bool pen_down) {
    BezierSegment s;
    s.pen_down = pen_down;
    s.p = {a,
           {a[0] + (b[0] - a[0]) / 3, a[1] + (b[1] - a[1]) / 3},
           {a[0] + 2 * (b[0] - a[0]) / 3, a[1] + 2 * (b[1] - a[1]) / 3},
           b};
    return s;
}

/// Quarter circles (the usual 0.5523 Bezier) of radius r around (cx, cy), counter-clockwise
/// from angle 0 in y-up terms.
std::vector<BezierSegment> circle(double cx, double cy, double r) {
    const double k = 0.5522847498 * r;
    std::vector<BezierSegment> out;
    const double c[4][2] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    for (int i = 0; i < 4; ++i) {
        const double* a = c[i];
        const double* b = c[(i + 1) % 4];
        BezierSegment s;
        s.p = {PathPoint{cx + r * a[0], cy + r * a[1]},
               PathPoint{cx + r * a[0] + k * b[0], cy + r * a[1] + k * b[1]},
               PathPoint{cx + r * b[0] + k * a[0], cy + r * b[1] + k * a[1]},
               PathPoint{cx + r * b[0], cy + r * b[1]}};
        out.push_back(s);
    }
    return out;
}

/// The test drawing: travel from the origin, a 40 mm square, travel, a circle of radius 12.
std::vector<BezierSegment> drawing() {
    std::vector<BezierSegment> g;
    g.push_back(straight({0, 0}, {10, 10}, false));
    g.push_back(straight({10, 10}, {50, 10}, true));
    g.push_back(straight({50, 10}, {50, 50}, true));
    g.push_back(straight({50, 50}, {10, 50}, true));
    g.push_back(straight({10, 50}, {10, 10}, true));
    g.push_back(straight({10, 10}, {82, 30}, false));
    for (const BezierSegment& s : circle(70, 30, 12)) g.push_back(s);
    return g;
}

PathPoint at(const BezierSegment& s, double u) {
    PathPoint p(2);
    for (int a = 0; a < 2; ++a) {
        const double v = 1 - u;
        p[a] = v * v * v * s.p[0][a] + 3 * v * v * u * s.p[1][a] + 3 * v * u * u * s.p[2][a] +
               u * u * u * s.p[3][a];
    }
    return p;
}

PathPoint d_at(const BezierSegment& s, double u) {
    PathPoint p(2);
    for (int a = 0; a < 2; ++a) {
        const double v = 1 - u;
        p[a] = 3 * v * v * (s.p[1][a] - s.p[0][a]) + 6 * v * u * (s.p[2][a] - s.p[1][a]) +
               3 * u * u * (s.p[3][a] - s.p[2][a]);
    }
    return p;
}

CoreSpan hermite(const std::vector<std::int32_t>& p0, const std::vector<std::int32_t>& p1,
                 const std::vector<std::int32_t>& t0, const std::vector<std::int32_t>& t1,
                 std::uint32_t ticks, bool pen_down) {
    CoreSpan s;
    s.basis = Basis::kHermite;
    s.ticks = ticks;
    s.pen_down = pen_down;
    REQUIRE(make_span_timing(s.basis, ticks, s.timing) == Status::kOk);
    for (std::size_t a = 0; a < p0.size(); ++a) {
        s.control.push_back({p0[a], p1[a], t0[a], t1[a]});
        const std::int32_t c[4] = {p0[a], p1[a], t0[a], t1[a]};
        TickCubic cubic;
        REQUIRE(make_tick_cubic(s.basis, c, s.timing, cubic) == Status::kOk);
        s.cubic.push_back(cubic);
    }
    return s;
}

/// A hand-timed plan (no planner): each segment rest to rest with the smooth-step time law
/// u = 3 tau^2 - 2 tau^3 (peak speed 1.5 x average, set to the feed), sampled every 8 ticks
/// into Hermite (position + velocity) spans; a 50 ms dwell where the pen changes.
Plan hand_timed_plan(const std::vector<BezierSegment>& g, const MachineProfile& m) {
    Plan plan;
    const double lsb = m.mm_per_lsb, hz = m.tick_hz;
    const std::uint32_t n = 8;
    const auto q = [&](double mm) { return static_cast<std::int32_t>(std::llround(mm / lsb)); };
    std::vector<std::int32_t> here = {q(g.front().p[0][0]), q(g.front().p[0][1])};
    bool pen = false;
    const auto add = [&](CoreSpan s) {
        if (s.pen_down != pen) plan.pen.push_back({plan.total_ticks, s.pen_down});
        pen = s.pen_down;
        plan.total_ticks += s.ticks;
        plan.spans.push_back(std::move(s));
    };
    for (const BezierSegment& s : g) {
        if (s.pen_down != pen) add(hermite(here, here, {0, 0}, {0, 0}, 50, s.pen_down));
        double length = 0;
        for (int i = 0; i < 200; ++i) {
            const PathPoint a = at(s, i / 200.0), b = at(s, (i + 1) / 200.0);
            length += std::hypot(b[0] - a[0], b[1] - a[1]);
        }
        (s.pen_down ? plan.path_length : plan.travel_length) += length;
        const double feed = s.pen_down ? m.feed : m.travel_feed;
        const double duration = 1.5 * length / feed;
        const auto spans = static_cast<std::uint32_t>(std::max(1.0, std::ceil(duration * hz / n)));
        const double total = spans * n / hz;
        std::vector<std::int32_t> prev_v = {0, 0};
        for (std::uint32_t i = 1; i <= spans; ++i) {
            const double tau = static_cast<double>(i) / spans;
            const double u = 3 * tau * tau - 2 * tau * tau * tau,
                         du = (6 * tau - 6 * tau * tau) / total;
            const PathPoint p = at(s, u), dp = d_at(s, u);
            std::vector<std::int32_t> next = {q(p[0]), q(p[1])};
            // Tangent over the span in LSB: velocity (mm/s) x span seconds / lsb.
            std::vector<std::int32_t> v = {q(dp[0] * du * n / hz), q(dp[1] * du * n / hz)};
            add(hermite(here, next, prev_v, v, n, s.pen_down));
            here = next;
            prev_v = v;
        }
    }
    add(hermite(here, here, {0, 0}, {0, 0}, 50, false));
    plan.duration = static_cast<double>(plan.total_ticks) / hz;
    return plan;
}

pugi::xml_document parse(const std::string& svg) {
    pugi::xml_document doc;
    const pugi::xml_parse_result r = doc.load_string(svg.c_str());
    INFO(r.description() << " at offset " << r.offset);
    REQUIRE(r);
    REQUIRE(std::string(doc.document_element().name()) == "svg");
    return doc;
}

std::vector<plot::Point> points_of(const pugi::xml_node& polyline) {
    std::vector<plot::Point> out;
    std::istringstream in(polyline.attribute("points").value());
    std::string pair;
    while (in >> pair) {
        const auto comma = pair.find(',');
        out.push_back({std::stod(pair.substr(0, comma)), std::stod(pair.substr(comma + 1))});
    }
    return out;
}

/// A series drawing the square at constant speed with rounded setpoints, pen down.
plot::TickSeries square_series(double side, std::size_t ticks_per_side) {
    plot::TickSeries s;
    s.name = "setpoints";
    s.axes = 2;
    s.quantum_mm = 0.001;
    const double corners[5][2] = {{0, 0}, {side, 0}, {side, side}, {0, side}, {0, 0}};
    for (int c = 0; c < 4; ++c) {
        for (std::size_t k = 0; k < ticks_per_side; ++k) {
            const double f = static_cast<double>(k) / static_cast<double>(ticks_per_side);
            for (int a = 0; a < 2; ++a) {
                const double mm = corners[c][a] + f * (corners[c + 1][a] - corners[c][a]);
                s.position.push_back(std::round(mm / 0.001) * 0.001);
            }
            s.pen_down.push_back(c == 3 ? 0 : 1);  // the last side pen-up
        }
    }
    s.position.push_back(0);
    s.position.push_back(0);
    s.pen_down.push_back(0);
    return s;
}

struct TempDir {
    fs::path path;
    TempDir() {
        path = fs::temp_directory_path() / ("pathstream_plot_test_" + std::to_string(getpid()));
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path, ec);
    }
};

std::string read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream o;
    o << in.rdbuf();
    return o.str();
}

}  // namespace

TEST_CASE("min/max decimation keeps every column's extremes and the ends", "[plot]") {
    std::mt19937 rng(42);
    std::normal_distribution<double> noise(0, 1);
    const std::size_t n = 200000, columns = 500;
    std::vector<double> x(n), y(n);
    for (std::size_t i = 0; i < n; ++i) {
        x[i] = static_cast<double>(i) * 0.001;
        y[i] = std::sin(x[i]) + 0.1 * noise(rng);
    }
    y[12345] = 40;  // one-sample spikes must survive
    y[150001] = -35;
    const auto d = plot::decimate_min_max(x, y, x.front(), x.back(), columns);
    CHECK(d.size() <= 2 * columns + 4);
    CHECK(d.size() >= columns);
    CHECK(d.front().x == x.front());
    CHECK(d.back().x == x.back());
    for (std::size_t i = 1; i < d.size(); ++i) REQUIRE(d[i].x >= d[i - 1].x);
    bool spike_up = false, spike_down = false;
    for (const auto& p : d) {
        spike_up |= p.y == 40 && p.x == x[12345];
        spike_down |= p.y == -35 && p.x == x[150001];
    }
    CHECK(spike_up);
    CHECK(spike_down);
    // Every column's own extremes are there.
    const double width = (x.back() - x.front()) / columns;
    for (std::size_t c = 0; c < columns; c += 37) {
        double lo = 1e9, hi = -1e9, dlo = 1e9, dhi = -1e9;
        for (std::size_t i = 0; i < n; ++i) {
            if (std::floor(x[i] / width) == static_cast<double>(c))
                lo = std::min(lo, y[i]), hi = std::max(hi, y[i]);
        }
        for (const auto& p : d) {
            if (std::floor(p.x / width) == static_cast<double>(c))
                dlo = std::min(dlo, p.y), dhi = std::max(dhi, p.y);
        }
        CHECK(dlo == lo);
        CHECK(dhi == hi);
    }
    // Short series come back whole; NaN samples are dropped.
    const std::vector<double> sx = {0, 1, 2}, sy = {1, NAN, 3};
    const auto small = plot::decimate_min_max(sx, sy, 0, 2, 500);
    REQUIRE(small.size() == 2);
    CHECK(small[1].y == 3);
}

TEST_CASE("differences of rounded setpoints recover velocity and acceleration", "[plot]") {
    // Constant acceleration 1000 mm/s^2 from rest, rounded to 1 um, 1 kHz.
    plot::TickSeries s;
    s.axes = 1;
    s.quantum_mm = 0.001;
    for (int k = 0; k < 1000; ++k) {
        const double t = k / 1000.0;
        s.position.push_back(std::round(500.0 * t * t / 0.001) * 0.001);
        s.pen_down.push_back(1);
    }
    MachineProfile m;
    m.axes = {{"x", 2000.0, 1000.0}};
    const plot::Derivatives d = plot::differentiate(s, m);
    // h: 2 q / (h T)^2 <= 5 % of 1000 mm/s^2  ->  h >= 6.3
    CHECK(d.half_window == 7);
    CHECK(d.acceleration_noise <= 50);
    for (std::size_t k = 10; k < 990; ++k) {
        REQUIRE(std::fabs(d.acceleration[k] - 1000) <= d.acceleration_noise);
        REQUIRE(std::fabs(d.velocity[k] - 1000 * (k / 1000.0)) <= 0.1);
        REQUIRE(d.speed[k] == std::fabs(d.velocity[k]));
    }
    CHECK(plot::differentiate(s, m, 1).half_window == 1);
    s.quantum_mm = 0;  // continuous series: one tick
    CHECK(plot::differentiate(s, m).half_window == 1);
}

TEST_CASE("path.svg is well-formed, equal-scale, y-down by default, with every series", "[plot]") {
    const MachineProfile m = profile_xy();
    const std::vector<BezierSegment> ideal = {
        straight({0, 0}, {40, 0}, true), straight({40, 0}, {40, 40}, true),
        straight({40, 40}, {0, 40}, true), straight({0, 40}, {0, 0}, false)};
    const plot::TickSeries exec = square_series(40, 8000);  // 5 um per tick: ~0.1 px
    plot::TickSeries plant = exec;
    plant.name = "servo plant";
    plot::Options o;
    o.title = "square & <test>";
    const auto doc = parse(plot::path_svg(ideal, exec, &plant, m, o));
    const pugi::xml_node svg = doc.document_element();
    CHECK(std::string(svg.child("text").text().get()).find("square & <test>") != std::string::npos);

    const pugi::xml_node ideal_g = svg.find_child_by_attribute("g", "id", "ideal-path");
    const pugi::xml_node set_g = svg.find_child_by_attribute("g", "id", "setpoints");
    const pugi::xml_node plant_g = svg.find_child_by_attribute("g", "id", "plant");
    REQUIRE(ideal_g);
    REQUIRE(set_g);
    REQUIRE(plant_g);
    CHECK(ideal_g.find_child_by_attribute("polyline", "class", "pen-down"));
    CHECK(ideal_g.find_child_by_attribute("polyline", "class", "pen-up")
              .attribute("stroke-dasharray"));
    CHECK(
        set_g.find_child_by_attribute("polyline", "class", "pen-up").attribute("stroke-dasharray"));

    // Equal scale: the ideal square is square in pixels. y down: y = 40 mm is below y = 0.
    const auto pts = points_of(ideal_g.find_child_by_attribute("polyline", "class", "pen-down"));
    REQUIRE(pts.size() >= 4);
    double x0 = 1e9, x1 = -1e9, y0 = 1e9, y1 = -1e9;
    for (const auto& p : pts)
        x0 = std::min(x0, p.x), x1 = std::max(x1, p.x), y0 = std::min(y0, p.y),
        y1 = std::max(y1, p.y);
    CHECK(std::fabs((x1 - x0) - (y1 - y0)) < 0.2);
    CHECK(pts.front().y < pts[pts.size() / 2].y);  // starts at y = 0 (top), passes y = 40
    // The setpoint polylines are thinned to distinct pixels: far fewer points than ticks.
    std::size_t set_points = 0;
    for (const pugi::xml_node pl : set_g.children("polyline")) set_points += points_of(pl).size();
    CHECK(set_points < 32000 / 4);
    CHECK(set_points > 20);

    std::string legend;
    for (const pugi::xml_node t :
         svg.find_child_by_attribute("g", "id", "legend").children("text")) {
        legend += std::string(t.text().get()) + "|";
    }
    CHECK(legend == "ideal path|ideal travel (pen up)|setpoints|servo plant|");
    CHECK(svg.find_child_by_attribute("g", "id", "axes")
              .find_child_by_attribute("text", "class", "tick-label"));

    o.y_up = true;
    const auto up = parse(plot::path_svg(ideal, exec, nullptr, m, o));
    const auto up_pts = points_of(up.document_element()
                                      .find_child_by_attribute("g", "id", "ideal-path")
                                      .find_child_by_attribute("polyline", "class", "pen-down"));
    CHECK(up_pts.front().y > up_pts[up_pts.size() / 2].y);
    CHECK_FALSE(up.document_element().find_child_by_attribute("g", "id", "plant"));

    // One axis: position against time.
    plot::TickSeries one;
    one.name = "setpoints";
    one.axes = 1;
    for (int k = 0; k < 100; ++k) one.position.push_back(k * 0.01), one.pen_down.push_back(1);
    MachineProfile m1 = m;
    m1.axes.resize(1);
    const auto d1 = parse(plot::path_svg({}, one, nullptr, m1, plot::Options{}));
    CHECK(d1.document_element().find_child_by_attribute("g", "id", "setpoints").child("polyline"));
}

TEST_CASE("speed.svg and acceleration.svg carry the series and the limit lines", "[plot]") {
    const MachineProfile m = profile_xy();
    const plot::TickSeries exec = square_series(40, 800);  // 50 mm/s along each side
    const auto speed = parse(plot::speed_svg(exec, m, plot::Options{}));
    const pugi::xml_node s = speed.document_element();
    const pugi::xml_node series = s.find_child_by_attribute("g", "id", "speed").child("polyline");
    REQUIRE(series);
    CHECK(points_of(series).size() <= 2 * 900);
    const pugi::xml_node feed = s.find_child_by_attribute("line", "id", "feed");
    const pugi::xml_node travel = s.find_child_by_attribute("line", "id", "travel-feed");
    REQUIRE(feed);
    REQUIRE(travel);
    CHECK(travel.attribute("y1").as_double() < feed.attribute("y1").as_double());  // 90 above 50
    const pugi::xml_node limits = s.find_child_by_attribute("g", "id", "velocity-limits");
    CHECK(std::distance(limits.children("line").begin(), limits.children("line").end()) == 2);
    CHECK(limits.find_child_by_attribute("line", "id", "velocity-limit-x"));
    CHECK(s.find_child_by_attribute("g", "id", "pen-up-intervals").child("rect"));
    // The plotted speed sits on the feed line along the sides (50 mm/s).
    std::size_t on_feed = 0;
    for (const auto& p : points_of(series))
        on_feed += std::fabs(p.y - feed.attribute("y1").as_double()) < 1.0;
    CHECK(on_feed > 100);

    const auto acc = parse(plot::acceleration_svg(exec, m, plot::Options{}));
    const pugi::xml_node a = acc.document_element();
    CHECK(a.find_child_by_attribute("g", "id", "acceleration-x").child("polyline"));
    CHECK(a.find_child_by_attribute("g", "id", "acceleration-y").child("polyline"));
    const pugi::xml_node alim = a.find_child_by_attribute("g", "id", "acceleration-limits");
    CHECK(std::distance(alim.children("line").begin(), alim.children("line").end()) == 4);
    CHECK(alim.find_child_by_attribute("line", "id", "acceleration-limit-y-negative"));

    // Six axes on a narrow plot: the legend wraps, the plot moves down, still well-formed.
    plot::TickSeries six;
    six.name = "setpoints";
    six.axes = 6;
    MachineProfile m6;
    for (int i = 0; i < 6; ++i) m6.axes.push_back({std::string(1, "xyzabc"[i]), 100.0, 1000.0});
    for (int k = 0; k < 500; ++k) {
        for (int i = 0; i < 6; ++i) six.position.push_back(std::sin(k * 0.01 * (i + 1)));
        six.pen_down.push_back(k < 250);
    }
    plot::Options narrow;
    narrow.width_px = 500;
    for (const std::string& svg :
         {plot::speed_svg(six, m6, narrow), plot::acceleration_svg(six, m6, narrow),
          plot::path_svg({}, six, nullptr, m6, narrow)}) {
        const auto doc6 = parse(svg);
        const pugi::xml_node root = doc6.document_element();
        CHECK(root.attribute("width").as_double() == 500);
        const pugi::xml_node moved = root.find_child_by_attribute("g", "id", "plot");
        if (moved)
            CHECK(std::string(moved.attribute("transform").value()).rfind("translate(0 ", 0) == 0);
    }
    CHECK(parse(plot::speed_svg(six, m6, narrow))
              .document_element()
              .find_child_by_attribute("g", "id", "plot"));
}

TEST_CASE("write_plots writes SVGs atomically and PNGs through rsvg-convert without a shell",
          "[plot]") {
    const MachineProfile m = profile_xy();
    const plot::TickSeries exec = square_series(40, 400);
    const std::vector<BezierSegment> ideal = {straight({0, 0}, {40, 0}, true)};
    TempDir dir;
    const fs::path odd = dir.path / "it's a \"dir\"; $(rm -rf x) &";  // nothing here is a command
    fs::create_directories(odd);
    const plot::WrittenPlots w =
        plot::write_plots(odd.string(), ideal, exec, nullptr, m, plot::Options{});
    for (const char* name : {"path.svg", "speed.svg", "acceleration.svg"}) {
        REQUIRE(fs::exists(odd / name));
        (void)parse(read_all(odd / name));
    }
    if (plot::find_rsvg_convert()) {
        REQUIRE(w.png);
        CHECK(w.files.size() == 6);
        for (const char* name : {"path.png", "speed.png", "acceleration.png"}) {
            const std::string png = read_all(odd / name);
            REQUIRE(png.size() > 1000);
            CHECK(png.compare(0, 8, "\x89PNG\r\n\x1a\n") == 0);
        }
        // A broken SVG: rsvg-convert's complaint comes back, and no PNG appears.
        std::ofstream(odd / "bad.svg") << "<svg xmlns=\"http://www.w3.org/2000/svg\"><g></svg>";
        try {
            plot::svg_to_png(*plot::find_rsvg_convert(), (odd / "bad.svg").string(),
                             (odd / "bad.png").string());
            FAIL("expected a runtime_error");
        } catch (const std::runtime_error& e) {
            CHECK(std::string(e.what()).find("rsvg-convert failed") != std::string::npos);
        }
        CHECK_FALSE(fs::exists(odd / "bad.png"));
    } else {
        WARN("rsvg-convert not on PATH: PNG conversion untested");
    }
    // No temporary files left behind.
    for (const auto& e : fs::directory_iterator(odd)) {
        CHECK(e.path().filename().string().find(".tmp-") == std::string::npos);
    }

    // Without rsvg-convert on PATH: SVGs only, and a note saying why.
    const char* old = std::getenv("PATH");
    const std::string saved = old ? old : "";
    setenv("PATH", dir.path.c_str(), 1);
    const plot::WrittenPlots none =
        plot::write_plots(dir.path.string(), ideal, exec, nullptr, m, plot::Options{});
    setenv("PATH", saved.c_str(), 1);
    CHECK_FALSE(none.png);
    CHECK(none.files.size() == 3);
    CHECK(none.note.find("rsvg-convert not found") != std::string::npos);

    CHECK_THROWS_AS(plot::write_plots((dir.path / "missing").string(), ideal, exec, nullptr, m,
                                      plot::Options{}),
                    std::runtime_error);
}

TEST_CASE("the report shows the run's figures", "[plot]") {
    const MachineProfile m = profile_xy();
    const plot::TickSeries exec = square_series(40, 800);
    Plan plan;
    plan.total_ticks = 3200;
    plan.duration = 3.2;
    plan.path_length = 120;
    plan.travel_length = 40;
    PlanCheck check;
    check.max_deviation = 0.0032;
    check.worst_deviation_tick = 1234;
    check.within_limits = true;
    // The allowance-subtracted fractions (whole-LSB steps) must not be what the report shows.
    check.max_velocity_fraction = 0.5;
    check.max_acceleration_fraction = 0.25;
    check.axis_velocity_fraction = {0.4234, 0.4987};
    check.axis_acceleration_fraction = {0.6667, 0.3333};
    check.axis_velocity_fraction_exact = {0.4321, 0.5012};
    check.axis_acceleration_fraction_exact = {0.9896, 0.7543};
    check.axis_max_step = {53, 51};
    check.axis_max_second_difference = {3, 2};
    check.axis_velocity_limit_lsb = {120, 100};
    check.axis_acceleration_limit_lsb = {2, 1.5};
    plot::RunSummary run;
    run.plant = "servo, 2nd order, f_n 50 Hz, zeta 1";
    run.ticks = 3201;
    run.spans = 400;
    run.pen_switches = 2;
    run.simulated_seconds = 3.201;
    run.wall_seconds = 0.05;
    run.max_following_error_mm = {0.8123, 0.3};
    run.rms_following_error_mm = {0.201, 0.1};
    const std::string text = plot::text_report(plan, &check, m, exec, run);
    INFO(text);
    for (const char* figure : {"3.200 s planned",
                               "3.201 s simulated in 0.050 s wall",
                               "(64x)",
                               "120.00 mm pen-down",
                               "40.00 mm travel",
                               "2 pen lifts and lowers",
                               "3201 ticks",
                               "400 spans",
                               "0 underruns",
                               "3.20 um max (tick 1234)",
                               "within the axis limits",
                               "812.3",
                               "201.0",
                               "servo, 2nd order",
                               "exact cubic peak: v 50.12 %, a 98.96 %",
                               "43.21",
                               "53 of 120",
                               "98.96",
                               "3 of 2",
                               "50.12",
                               "51 of 100",
                               "75.43",
                               "2 of 1.5",
                               "LSB/tick^2",
                               "following error um"}) {
        CHECK(text.find(figure) != std::string::npos);
    }
    for (const char* allowance : {"42.3", "49.9", "66.7", "33.3"})
        CHECK(text.find(allowance) == std::string::npos);
    // Executed peaks: 50 mm/s on each axis against 120 and 100 mm/s limits.
    CHECK(text.find("41.7") != std::string::npos);
    CHECK(text.find("50.0") != std::string::npos);
    std::istringstream lines(text);
    std::size_t count = 0;
    for (std::string line; std::getline(lines, line); ++count) CHECK(line.size() <= 80);
    CHECK(count <= 24);

    // Over the limits: the exact figure says so; setpoints over limit + rounding get a line.
    check.within_limits = false;
    check.axis_acceleration_fraction_exact = {1.2, 0.7543};
    check.max_acceleration_fraction = 1.1;
    const std::string over = plot::text_report(plan, &check, m, exec, run);
    CHECK(over.find("LIMITS EXCEEDED (exact cubic peak: v 50.12 %, a 120.00 %)") !=
          std::string::npos);
    CHECK(over.find("setpoint differences over limit + rounding (v 50.0 %, a 110.0 %)") !=
          std::string::npos);
    CHECK(text.find("over limit + rounding") == std::string::npos);

    run.max_following_error_mm.clear();
    run.underruns = 7;
    const std::string ideal = plot::text_report(plan, nullptr, m, exec, run);
    CHECK(ideal.find("not checked") != std::string::npos);
    CHECK(ideal.find("ideal plant") != std::string::npos);
    CHECK(ideal.find("ran dry 7 times") != std::string::npos);
}

TEST_CASE("a drawing simulated on the servo plant, plotted and reported end to end",
          "[plot][sim]") {
    const MachineProfile m = profile_xy();
    const std::vector<BezierSegment> g = drawing();
    const Plan plan = hand_timed_plan(g, m);
    sim::SimOptions options;
    options.plant = sim::PlantModel::kServo;
    options.servo.bandwidth_hz = 30;
    options.settle_ticks = 100;
    const sim::SimulationResult r = sim::simulate(plan.spans, m, options);
    CHECK(r.underruns == 0);
    CHECK(r.pen_switch_ticks.size() == 4);
    REQUIRE(plan.pen.size() == 4);
    for (std::size_t i = 0; i < 4; ++i) CHECK(r.pen_switch_ticks[i] == plan.pen[i].tick);

    const plot::TickSeries setpoints = host::setpoint_series(r), plant = host::plant_series(r);
    const char* keep = std::getenv("PATHSTREAM_PLOT_DIR");
    TempDir temp;
    const fs::path out = keep != nullptr ? fs::path(keep) : temp.path;
    fs::create_directories(out);
    plot::Options o;
    o.title = "square and circle, servo 30 Hz";
    const plot::WrittenPlots w = plot::write_plots(out.string(), g, setpoints, &plant, m, o);
    CHECK(w.files.size() >= 3);
    for (const std::string& f : w.files) {
        if (f.size() > 4 && f.compare(f.size() - 4, 4, ".svg") == 0)
            CHECK(fs::file_size(f) < 400000);
    }
    const std::string report = plot::text_report(plan, nullptr, m, setpoints, host::run_summary(r));
    CHECK(report.find("4 pen lifts and lowers") != std::string::npos);
    if (keep != nullptr) std::ofstream(out / "report.txt") << report;
}

namespace {

/// A series of `n` ticks on `axes` axes: wavy motion rounded to the LSB, pen changes.
plot::TickSeries wavy_series(std::size_t n, std::size_t axes) {
    plot::TickSeries s;
    s.name = "setpoints";
    s.axes = axes;
    s.quantum_mm = 0.001;
    for (std::size_t k = 0; k < n; ++k) {
        const double t = static_cast<double>(k) * 0.001;
        for (std::size_t a = 0; a < axes; ++a) {
            const double mm = 20 * std::sin(1.3 * t + a) + 3 * std::sin(17.0 * t * (a + 1));
            s.position.push_back(std::round(mm / 0.001) * 0.001);
        }
        s.pen_down.push_back((k / 700) % 3 != 2 ? 1 : 0);
    }
    return s;
}

plot::RunRecord recorded(const plot::TickSeries& s, const plot::TickSeries* plant,
                         const MachineProfile& m, std::size_t capacity, unsigned h = 0) {
    plot::RunRecorder recorder(m, s.axes, s.tick_hz, s.quantum_mm, plant != nullptr, capacity, h);
    for (std::size_t k = 0; k < s.ticks(); ++k) {
        recorder.add(s.position.data() + k * s.axes,
                     plant != nullptr ? plant->position.data() + k * s.axes : nullptr,
                     s.pen_down[k] != 0);
    }
    plot::RunRecord r = recorder.finish();
    r.executed_name = s.name;
    if (plant != nullptr) r.plant_name = plant->name;
    return r;
}

MachineProfile profile_axes(std::size_t axes) {
    MachineProfile m;
    for (std::size_t a = 0; a < axes; ++a)
        m.axes.push_back({std::string(1, "xyz"[a]), 120.0, 2000.0});
    m.mm_per_lsb = 0.001;
    m.tick_hz = 1000;
    m.feed = 50;
    m.travel_feed = 90;
    return m;
}

}  // namespace

TEST_CASE("a recorder seeing the ticks one by one gives the whole series' figures exactly",
          "[plot]") {
    for (std::size_t axes : {1, 2, 3}) {
        const MachineProfile m = profile_axes(axes);
        // Around the window (h = 4 here: 2 h + 1 = 9 ticks) and long ones.
        for (std::size_t n : {0, 1, 2, 3, 5, 8, 9, 10, 17, 1000, 30000}) {
            for (unsigned h : {0u, 1u, 7u}) {
                INFO("axes " << axes << " ticks " << n << " half window " << h);
                const plot::TickSeries s = wavy_series(n, axes);
                const plot::ExecutedFigures whole = plot::executed_figures(s, m, h);
                for (std::size_t capacity : {std::size_t{0}, std::size_t{64}}) {
                    const plot::ExecutedFigures f = recorded(s, nullptr, m, capacity, h).figures;
                    CHECK(f.ticks == whole.ticks);
                    CHECK(f.pen_down_ticks == whole.pen_down_ticks);
                    CHECK(f.pen_downs == whole.pen_downs);
                    CHECK(f.pen_ups == whole.pen_ups);
                    CHECK(f.half_window == whole.half_window);
                    CHECK(f.acceleration_noise == whole.acceleration_noise);
                    CHECK(f.peak_velocity == whole.peak_velocity);
                    CHECK(f.peak_acceleration == whole.peak_acceleration);
                    CHECK(f.peak_speed == whole.peak_speed);
                }
            }
        }
    }
}

TEST_CASE("a record keeps every tick until its capacity, then stays within it", "[plot]") {
    const MachineProfile m = profile_xy();
    SECTION("short: the same plots as the whole series") {
        const plot::TickSeries s = wavy_series(5000, 2);
        plot::TickSeries plant = s;
        plant.name = "servo plant";
        plant.quantum_mm = 0;
        for (double& v : plant.position) v += 0.0123;
        const plot::RunRecord r = recorded(s, &plant, m, 8192);
        CHECK_FALSE(r.thinned);
        const std::vector<BezierSegment> ideal = {straight({0, 0}, {20, 20}, true)};
        VectorSegmentSource source(ideal);
        plot::Options o;
        CHECK(plot::path_svg(source, r, m, o) == plot::path_svg(ideal, s, &plant, m, o));
        CHECK(plot::speed_svg(r, m, o) == plot::speed_svg(s, m, o));
        CHECK(plot::acceleration_svg(r, m, o) == plot::acceleration_svg(s, m, o));
        const plot::TickSeries one = wavy_series(3000, 1);
        const MachineProfile m1 = profile_axes(1);
        VectorSegmentSource none_source(ideal);
        CHECK(plot::path_svg(none_source, recorded(one, nullptr, m1, 8192), m1, o) ==
              plot::path_svg(ideal, one, nullptr, m1, o));
    }
    SECTION("long: bounded, peaks and ends kept") {
        const std::size_t capacity = 512;
        const plot::TickSeries s = wavy_series(200000, 2);
        plot::TickSeries plant = s;
        const plot::RunRecord r = recorded(s, &plant, m, capacity);
        const plot::RunRecord whole = recorded(s, &plant, m, 0);
        CHECK(r.thinned);
        CHECK_FALSE(whole.thinned);
        CHECK(r.speed.size() <= 2 * capacity + 2);
        for (const auto& a : r.acceleration) CHECK(a.size() <= 2 * capacity + 2);
        CHECK(r.executed_path.size() <= 8 * capacity + 1);
        CHECK(r.plant_path.size() <= 8 * capacity + 1);
        CHECK(r.executed_path.size() < s.ticks() / 10);
        CHECK(r.pen_up.size() <= capacity);
        CHECK(whole.speed.size() == s.ticks());
        CHECK(whole.executed_path.size() == s.ticks());
        // The figures are over every tick; the envelope keeps the peak and both ends.
        CHECK(r.figures.peak_speed == whole.figures.peak_speed);
        double peak = 0;
        for (const plot::Point& p : r.speed) peak = std::max(peak, p.y);
        CHECK(peak == r.figures.peak_speed);
        CHECK(r.speed.front().x == 0);
        CHECK(r.speed.back().x == Approx(199.999));
        CHECK(r.executed_path.front().x == s.at(0, 0));
        CHECK(r.executed_path.back().x == s.at(s.ticks() - 1, 0));
        CHECK(r.executed_path.back().y == s.at(s.ticks() - 1, 1));
        // 95 pen-up intervals of 700 ticks: all kept, each whole.
        REQUIRE(r.pen_up == whole.pen_up);
        CHECK(r.pen_up.size() == 95);
        CHECK(r.pen_up.front() == std::pair<std::uint64_t, std::uint64_t>{1400, 2100});
        // Every kept point is a tick of the series, in order.
        std::size_t k = 0;
        for (const plot::TracePoint& p : r.executed_path) {
            while (k < s.ticks() && !(s.at(k, 0) == p.x && s.at(k, 1) == p.y)) ++k;
            REQUIRE(k < s.ticks());
        }
        const std::vector<BezierSegment> ideal = {straight({0, 0}, {20, 20}, true)};
        VectorSegmentSource source(ideal);
        plot::Options o;
        const std::string svg = plot::path_svg(source, r, m, o);
        CHECK(svg.size() < plot::path_svg(ideal, s, &plant, m, o).size() * 2);
    }
    SECTION("many pen changes: merged and thinned, the figures still exact") {
        const std::size_t capacity = 64;
        plot::TickSeries s = wavy_series(40000, 2);
        for (std::size_t k = 0; k < s.ticks(); ++k) s.pen_down[k] = (k / 10) % 2;
        const plot::RunRecord r = recorded(s, nullptr, m, capacity);
        const plot::ExecutedFigures whole = plot::executed_figures(s, m);
        CHECK(r.figures.pen_downs == whole.pen_downs);
        CHECK(r.figures.pen_ups == whole.pen_ups);
        CHECK(r.figures.pen_down_ticks == whole.pen_down_ticks);
        CHECK(r.figures.peak_acceleration == whole.peak_acceleration);
        CHECK(r.pen_up.size() <= capacity);
        CHECK(r.executed_path.size() <= 8 * capacity + 1);
        // The merged intervals still cover every pen-up tick, in order.
        for (std::size_t i = 1; i < r.pen_up.size(); ++i)
            CHECK(r.pen_up[i - 1].second < r.pen_up[i].first);
        std::size_t i = 0;
        for (std::size_t k = 0; k < s.ticks(); ++k) {
            if (s.pen_down[k] != 0) continue;
            while (i < r.pen_up.size() && r.pen_up[i].second <= k) ++i;
            REQUIRE(i < r.pen_up.size());
            REQUIRE(r.pen_up[i].first <= k);
        }
    }
}
