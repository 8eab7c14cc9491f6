// The 3-D view of a machine with x, y and z axes: the isometric projection on hand-computed
// points, the axes found by name, path.svg in the isometric view with its dashed rapids, z.svg,
// and plotters' plots left as they were.
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <pugixml.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "pathstream/host/isometric.hpp"
#include "pathstream/host/plot.hpp"

using namespace pathstream;
using namespace pathstream::host;
namespace fs = std::filesystem;

namespace {

MachineProfile router() {
    MachineProfile m;
    m.axes = {{"x", 250.0, 2000.0}, {"y", 250.0, 2000.0}, {"z", 100.0, 1000.0}};
    m.feed = 40;
    m.travel_feed = 200;
    return m;
}

BezierSegment straight3(PathPoint a, PathPoint b, bool pen_down) {
    BezierSegment s;
    s.pen_down = pen_down;
    PathPoint c1(3), c2(3);
    for (int i = 0; i < 3; ++i) {
        c1[i] = a[i] + (b[i] - a[i]) / 3;
        c2[i] = a[i] + 2 * (b[i] - a[i]) / 3;
    }
    s.p = {a, c1, c2, b};
    return s;
}

struct Leg {
    PathPoint to;
    bool pen_down;
};

// A router's job: a rapid to above the cut, a plunge, a cut along +x, a retract and a rapid
// along +y (the retract and the last rapid pen-up), from (0, 0, 0).
const std::vector<Leg> kLegs = {{{10, 10, -5}, false},
                                {{10, 10, -12}, true},
                                {{50, 10, -12}, true},
                                {{50, 10, -5}, false},
                                {{50, 40, -5}, false}};

std::vector<BezierSegment> job() {
    std::vector<BezierSegment> g;
    PathPoint here = {0, 0, 0};
    for (const Leg& l : kLegs) {
        g.push_back(straight3(here, l.to, l.pen_down));
        here = l.to;
    }
    return g;
}

/// The job at 200 ticks a leg, straight at constant speed per leg.
plot::TickSeries job_series(const std::string& name, double lag_mm = 0) {
    plot::TickSeries s;
    s.name = name;
    s.axes = 3;
    PathPoint here = {0, 0, 0};
    for (const Leg& l : kLegs) {
        for (int k = 0; k < 200; ++k) {
            for (int a = 0; a < 3; ++a)
                s.position.push_back(here[a] + (l.to[a] - here[a]) * k / 200.0 + lag_mm);
            s.pen_down.push_back(l.pen_down ? 1 : 0);
        }
        here = l.to;
    }
    for (int a = 0; a < 3; ++a) s.position.push_back(here[a] + lag_mm);
    s.pen_down.push_back(0);
    return s;
}

pugi::xml_document parse(const std::string& svg) {
    pugi::xml_document doc;
    REQUIRE(doc.load_string(svg.c_str()));
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

pugi::xml_node group(const pugi::xml_document& doc, const char* id) {
    return doc.document_element().find_child_by_attribute("g", "id", id);
}

std::string texts(const pugi::xml_node& g) {
    std::string out;
    for (const pugi::xml_node t : g.children("text")) out += std::string(t.text().get()) + "|";
    return out;
}

}  // namespace

TEST_CASE("the 3-D plots' isometric view puts hand-computed points where the docs say",
          "[plot][isometric]") {
    const double c = std::sqrt(3.0) / 2;  // cos 30 deg
    const struct {
        double x, y, z, right, up;
    } cases[] = {
        {0, 0, 0, 0, 0},          {10, 0, 0, 10 * c, -5},  // +x: to the lower right, 30 deg down
        {0, 10, 0, 10 * c, 5},                             // +y: to the upper right, 30 deg up
        {0, 0, 10, 0, 10},                                 // +z: straight up
        {10, 10, 10, 20 * c, 10}, {3, -1, 2, 2 * c, 0},   {-4, 6, -1, 2 * c, 4},
    };
    for (const auto& k : cases) {
        const IsometricPoint p = isometric(k.x, k.y, k.z);
        INFO(k.x << ", " << k.y << ", " << k.z);
        CHECK(p.right == Approx(k.right).margin(1e-12));
        CHECK(p.up == Approx(k.up).margin(1e-12));
    }
    // A length along any axis keeps its length; the x-y diagonal is horizontal.
    for (const IsometricPoint p : {isometric(7, 0, 0), isometric(0, 7, 0), isometric(0, 0, 7)})
        CHECK(std::hypot(p.right, p.up) == Approx(7));
    CHECK(isometric(5, 5, 0).up == 0);
    // Linear: the view of a sum is the sum of the views (parallel lines stay parallel).
    const IsometricPoint a = isometric(1.5, -2, 4), b = isometric(-3, 7, 0.5),
                         s = isometric(-1.5, 5, 4.5);
    CHECK(s.right == Approx(a.right + b.right));
    CHECK(s.up == Approx(a.up + b.up));
}

TEST_CASE("the 3-D plots take the axes named x, y and z, in any order", "[plot][isometric]") {
    MachineProfile m = router();
    REQUIRE(xyz_axes(m));
    CHECK(xyz_axes(m)->x == 0);
    CHECK(xyz_axes(m)->z == 2);
    m.axes = {{"z", 100.0, 1000.0}, {"a", 50.0, 500.0}, {"y", 250.0, 2000.0}, {"x", 250.0, 2000.0}};
    REQUIRE(xyz_axes(m));
    CHECK(xyz_axes(m)->x == 3);
    CHECK(xyz_axes(m)->y == 2);
    CHECK(xyz_axes(m)->z == 0);
    m.axes = {{"x", 250.0, 2000.0}, {"y", 250.0, 2000.0}};
    CHECK_FALSE(xyz_axes(m));  // a plotter
    m.axes = {{"x", 250.0, 2000.0}, {"y", 250.0, 2000.0}, {"a", 50.0, 500.0}};
    CHECK_FALSE(xyz_axes(m));
    m.axes = {{"X", 250.0, 2000.0}, {"Y", 250.0, 2000.0}, {"Z", 100.0, 1000.0}};
    CHECK_FALSE(xyz_axes(m));  // the profile's names are lower case
}

TEST_CASE("path.svg of a 3-axis run plots the isometric view with dashed rapids",
          "[plot][isometric]") {
    const MachineProfile m = router();
    const plot::TickSeries exec = job_series("setpoints");
    const plot::TickSeries plant = job_series("servo plant", 0.01);
    const auto doc = parse(plot::path_svg(job(), exec, &plant, m, plot::Options{}));
    CHECK(std::string(doc.document_element().child("text").text().get()) == "Path (isometric)");
    const pugi::xml_node ideal = group(doc, "ideal-path"), set = group(doc, "setpoints");
    REQUIRE(ideal);
    REQUIRE(set);
    CHECK(group(doc, "plant"));
    CHECK(group(doc, "bounding-box").child("polyline"));
    CHECK_FALSE(group(doc, "axes"));  // no 2-D grid
    // Rapids dashed, feed moves solid: the ideal path's and the executed motion's.
    CHECK(std::string(ideal.find_child_by_attribute("polyline", "class", "pen-up")
                          .attribute("stroke-dasharray")
                          .value()) == "10 6");
    CHECK_FALSE(ideal.find_child_by_attribute("polyline", "class", "pen-down")
                    .attribute("stroke-dasharray"));
    CHECK(std::string(set.find_child_by_attribute("polyline", "class", "pen-up")
                          .attribute("stroke-dasharray")
                          .value()) == "6 4");
    CHECK(set.find_child_by_attribute("polyline", "class", "pen-down"));
    // The arrows are named by the axes, the scale bar is a nice length near a quarter of the
    // largest extent (x: 50 mm -> 10 mm).
    CHECK(texts(group(doc, "axis-arrows")) == "x|y|z|");
    CHECK(texts(group(doc, "scale")) == "10 mm|");
    std::string legend = texts(group(doc, "legend"));
    CHECK(legend == "ideal path (feed)|ideal rapids (pen up)|setpoints|servo plant|");

    // The feed moves in pixels: the plunge (10, 10, -5) -> (10, 10, -12) straight down, the
    // cut -> (50, 10, -12) along +x at 30 deg below the horizontal, and both at one scale.
    const auto pts = points_of(ideal.find_child_by_attribute("polyline", "class", "pen-down"));
    REQUIRE(pts.size() >= 3);
    const plot::Point top = pts.front(), end = pts.back();
    plot::Point bottom = top;
    for (const plot::Point& p : pts) {
        if (std::fabs(p.x - top.x) < 0.05 && p.y > bottom.y) bottom = p;
    }
    const double plunge = bottom.y - top.y;
    REQUIRE(plunge > 20);
    CHECK((end.y - bottom.y) / (end.x - bottom.x) == Approx(std::tan(M_PI / 6)).epsilon(0.005));
    CHECK(std::hypot(end.x - bottom.x, end.y - bottom.y) / plunge ==
          Approx(40.0 / 7).epsilon(0.005));
    // From the plunge's top to the cut's end: (40, 0, -7) mm -> right 40 cos 30, down 7 + 20.
    CHECK((end.y - top.y) / (end.x - top.x) ==
          Approx(27 / (40 * std::sqrt(3.0) / 2)).epsilon(0.005));
}

TEST_CASE("z.svg plots z against time, commanded and executed", "[plot][isometric]") {
    const MachineProfile m = router();
    const plot::TickSeries exec = job_series("setpoints");
    const plot::TickSeries plant = job_series("servo plant", 0.01);
    const plot::RunRecord r = plot::record_of(exec, &plant, m);
    REQUIRE(r.xyz);
    CHECK(r.lo[0][2] == -12);
    CHECK(r.hi[0][2] == 0);
    const auto doc = parse(plot::z_svg(r, m, plot::Options{}));
    CHECK(std::string(doc.document_element().child("text").text().get()) == "z against time");
    const pugi::xml_node set = group(doc, "setpoints"), pl = group(doc, "plant");
    REQUIRE(set.child("polyline"));
    REQUIRE(pl.child("polyline"));
    CHECK(group(doc, "pen-up-intervals").child("rect"));
    CHECK(texts(group(doc, "legend")) ==
          "setpoints (commanded)|servo plant (executed)|pen up (rapids)|");
    // Every tick is kept (1001 ticks): the lowest setpoint is the cut's z, lowest on the plot.
    const auto pts = points_of(set.child("polyline"));
    CHECK(pts.size() == exec.ticks());
    double lowest = 0;
    std::size_t at = 0;
    for (std::size_t k = 0; k < pts.size(); ++k) {
        if (pts[k].y > lowest) lowest = pts[k].y, at = k;
    }
    CHECK(exec.at(at, 2) == Approx(-12).margin(0.01));
    // Without a plant the setpoints are the only line, and the note says so.
    const auto alone = parse(plot::z_svg(plot::record_of(exec, nullptr, m), m, plot::Options{}));
    CHECK_FALSE(group(alone, "plant"));
    std::string note;
    for (const pugi::xml_node t : alone.document_element().children("text"))
        if (std::string(t.attribute("class").value()) == "note")
            note += std::string(t.text().get()) + " ";
    CHECK(note.find("(ideal plant) they are one line") != std::string::npos);
}

TEST_CASE("write_plots adds z.svg for a 3-axis machine and only then", "[plot][isometric]") {
    const fs::path dir =
        fs::temp_directory_path() / ("pathstream_plot_3d_" + std::to_string(getpid()));
    fs::create_directories(dir / "router");
    fs::create_directories(dir / "plotter");
    const plot::WrittenPlots w =
        plot::write_plots((dir / "router").string(), job(), job_series("setpoints"), nullptr,
                          router(), plot::Options{});
    for (const char* name : {"path.svg", "speed.svg", "acceleration.svg", "z.svg"})
        CHECK(fs::exists(dir / "router" / name));
    CHECK(w.files.size() == (w.png ? 8u : 4u));
    if (w.png) CHECK(fs::exists(dir / "router" / "z.png"));

    // A plotter, and a 3-axis machine without a z: the plots they always had.
    MachineProfile plotter = router();
    plotter.axes.resize(2);
    plot::TickSeries flat = job_series("setpoints");
    std::vector<double> xy;
    for (std::size_t k = 0; k < flat.ticks(); ++k)
        xy.push_back(flat.at(k, 0)), xy.push_back(flat.at(k, 1));
    flat.position = xy;
    flat.axes = 2;
    std::vector<BezierSegment> flat_job = job();
    for (BezierSegment& s : flat_job)
        for (PathPoint& p : s.p) p.resize(2);
    const plot::WrittenPlots w2 = plot::write_plots((dir / "plotter").string(), flat_job, flat,
                                                    nullptr, plotter, plot::Options{});
    CHECK(w2.files.size() == (w2.png ? 6u : 3u));
    CHECK_FALSE(fs::exists(dir / "plotter" / "z.svg"));
    const auto doc = parse(plot::path_svg(flat_job, flat, nullptr, plotter, plot::Options{}));
    CHECK(std::string(doc.document_element().child("text").text().get()) == "Path");
    CHECK_FALSE(group(doc, "axis-arrows"));
    MachineProfile xya = router();
    xya.axes[2].name = "a";
    const auto doc2 =
        parse(plot::path_svg(job(), job_series("setpoints"), nullptr, xya, plot::Options{}));
    CHECK(std::string(doc2.document_element().child("text").text().get()) == "Path");
    CHECK_THROWS_AS(plot::z_svg(plot::record_of(flat, nullptr, plotter), plotter, plot::Options{}),
                    std::invalid_argument);
    std::error_code ec;
    fs::remove_all(dir, ec);
}
