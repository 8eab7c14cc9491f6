#include "plan_paths.hpp"

#include <cmath>
#include <random>
#include <stdexcept>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/job_request.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/path_order.hpp"
#include "pathstream/host/svg_path.hpp"

namespace pathstream::bench {

using host::Path;
using host::PathBasis;
using host::Subpath;

namespace {
constexpr double kPi = 3.14159265358979323846;

Path one_subpath(Subpath s) {
    Path p;
    p.subpaths = {std::move(s)};
    return p;
}

}  // namespace

host::MachineProfile bench_pen_plotter() {
    host::MachineProfile p;
    p.axes = {{"x", 250, 3000}, {"y", 250, 3000}};
    p.mm_per_lsb = 0.001;
    p.tick_hz = 1000;
    p.ticks_per_span = 8;
    p.feed = 80;
    p.travel_feed = 200;
    p.pen_down_delay = 0.08;
    p.pen_up_delay = 0.06;
    p.chord_tolerance = 0.005;
    return p;
}

Path rose_path(std::size_t n) {
    Subpath s;
    s.basis = PathBasis::kBSpline;
    s.closed = true;
    for (std::size_t i = 0; i < n; ++i) {
        const double t = 2 * kPi * static_cast<double>(i) / static_cast<double>(n);
        const double r = 60 * std::cos(7 * t);
        s.points.push_back({r * std::cos(t), r * std::sin(t)});
    }
    return one_subpath(std::move(s));
}

Path wander_path(std::size_t n) {
    std::mt19937_64 rng(20261122);
    std::normal_distribution<double> turn(0, 0.25);
    Subpath s;
    s.basis = PathBasis::kBSpline;
    s.points.reserve(n, 2);
    double x = 0, y = 0, heading = 0;
    for (std::size_t i = 0; i + 1 < n; ++i) {
        s.points.push_back({x, y});
        heading += turn(rng);
        x += 1.5 * std::cos(heading);
        y += 1.5 * std::sin(heading);
        // stay within a 200 mm square: steer back towards the centre near the edges
        if (std::fabs(x) > 100 || std::fabs(y) > 100) heading = std::atan2(-y, -x) + turn(rng);
    }
    s.points.push_back({x, y});
    return one_subpath(std::move(s));
}

Path spiral_path(std::size_t n) {
    Subpath s;
    s.basis = PathBasis::kPolyline;
    const double turns = 20, pitch = 3;  // mm between turns
    for (std::size_t i = 0; i <= n; ++i) {
        const double t = 2 * kPi * turns * static_cast<double>(i) / static_cast<double>(n);
        const double r = 5 + pitch * t / (2 * kPi);
        s.points.push_back({r * std::cos(t), r * std::sin(t)});
    }
    return one_subpath(std::move(s));
}

Path random_polyline(std::size_t n, double min_turn, double max_turn, unsigned seed) {
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> turn(min_turn, max_turn), length(1, 6);
    std::bernoulli_distribution left(0.5);
    Subpath s;
    s.basis = PathBasis::kPolyline;
    double x = 0, y = 0, heading = 0;
    s.points.push_back({x, y});
    for (std::size_t i = 0; i < n; ++i) {
        heading += left(rng) ? turn(rng) : -turn(rng);
        // stay within a 200 mm square: head back towards the centre (a sharp turn of its own)
        if (std::fabs(x) > 100 || std::fabs(y) > 100) heading = std::atan2(-y, -x);
        const double l = length(rng);
        x += l * std::cos(heading);
        y += l * std::sin(heading);
        s.points.push_back({x, y});
    }
    return one_subpath(std::move(s));
}

Path read_example(const std::string& file, const host::MachineProfile& machine) {
    host::JobRequest request;  // what `pathstream plan FILE` reads with default options
    request.file = file;
    request.csv_basis = "polyline";  // the repository's CSV drawings are closed polylines
    request.csv_closed = true;
    request.order = true;  // G-code too: the benches have always timed ordered drawings
    return host::load_path(request, &machine);
}

}  // namespace pathstream::bench
