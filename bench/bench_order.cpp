// bench_order: how much pen-up travel (and motion time) does ordering the subpaths save?
//
// CMake lines to add to bench/CMakeLists.txt (not added here: another change owns that file):
//
//   # bench_order: pen-up travel of the example drawings and a random-segments drawing in
//   # document order, plain greedy and greedy + 2-opt/Or-opt, and the planned motion time
//   # before and after (docs/path-order.md). Exit 1 if an order has more travel than the
//   # document order or greedy + improvement more than greedy, 2 on a usage error.
//   #   build/bench/bench/bench_order [--quick] [--no-plan] [--markdown]
//   add_executable(bench_order bench_order.cpp)
//   target_link_libraries(bench_order PRIVATE pathstream_host)
//   target_compile_options(bench_order PRIVATE ${PATHSTREAM_HOST_WARNINGS} -O2)
//   target_compile_definitions(bench_order PRIVATE PATHSTREAM_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
//   add_test(NAME bench_order_smoke COMMAND bench_order --quick)
//   set_tests_properties(bench_order_smoke PROPERTIES LABELS bench TIMEOUT 300)
//
// Drawings: examples/landscape.svg, rose.json, leaf.ngc, star.csv (closed polyline, as its
// header says) and "random": --segments (2,000) straight strokes of 2..12 mm at seeded random
// places in 300 x 200 mm. Travel is straight pen-up distance from the origin (the machine's
// start) through every subpath end to the next start. Columns:
//   * document : the file's order and directions;
//   * greedy   : nearest neighbour with reversal and closed-start choice (joins applied);
//   * improved : greedy then 2-opt, Or-opt and start refinement (what the CLI does);
//   * order ms : wall time of the improved order (printed, never judged);
//   * motion s : planned duration (pen dwells included) with examples/machines/pen_plotter.json's
//                values, lead-in from the origin, document order -> improved order.
// Usage: bench_order [--quick] [--no-plan] [--segments N] [--markdown] [--help]
// Exit status: 0 every figure as expected, 1 an order lost to the document order or to greedy,
// 2 usage error, 3 a drawing could not be read or planned.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <random>
#include <string>
#include <vector>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/path_order.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/svg_path.hpp"

using namespace pathstream::host;

namespace {

#ifdef PATHSTREAM_SOURCE_DIR
const std::string kSource = PATHSTREAM_SOURCE_DIR;
#else
const std::string kSource = ".";
#endif

/// examples/machines/pen_plotter.json's values.
MachineProfile pen_plotter() {
    MachineProfile p;
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

/// n straight strokes at seeded random places.
Path random_segments(std::size_t n) {
    std::mt19937_64 rng(20240611);
    std::uniform_real_distribution<double> x(0, 300), y(0, 200), angle(0, 6.283185307179586),
        length(2, 12);
    Path p;
    for (std::size_t i = 0; i < n; ++i) {
        const double x0 = x(rng), y0 = y(rng), a = angle(rng), l = length(rng);
        p.subpaths.push_back({PathBasis::kPolyline,
                              false,
                              {{x0, y0}, {x0 + l * std::cos(a), y0 + l * std::sin(a)}},
                              0,
                              {}});
    }
    return p;
}

/// Planned duration (s) from the origin, or a negative value if planning failed.
double motion_seconds(const Path& path) {
    std::vector<BezierSegment> segments = to_bezier_segments(path);
    prepend_lead_in(segments, PathPoint(path.axes, 0.0));
    return plan_path(segments, pen_plotter()).duration;
}

void usage(FILE* out) {
    std::fprintf(
        out,
        "usage: bench_order [--quick] [--no-plan] [--segments N] [--markdown] [--help]\n"
        "exit: 0 ok, 1 an order lost to document order or greedy, 2 usage, 3 unreadable drawing\n");
}

}  // namespace

int main(int argc, char** argv) {
    bool quick = false, plan = true, markdown = false;
    std::size_t segments = 2000;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--quick") {
            quick = true, segments = 300;
        } else if (a == "--no-plan") {
            plan = false;
        } else if (a == "--markdown") {
            markdown = true;
        } else if (a == "--segments" && i + 1 < argc) {
            segments = std::strtoull(argv[++i], nullptr, 10);
            if (segments == 0) return usage(stderr), 2;
        } else if (a == "--help") {
            usage(stdout);
            return 0;
        } else {
            usage(stderr);
            return 2;
        }
    }
    struct Drawing {
        std::string name;
        Path path;
    };
    std::vector<Drawing> drawings;
    try {
        drawings.push_back({"landscape.svg", load_svg_path(kSource + "/examples/landscape.svg")});
        drawings.push_back({"rose.json", load_json_path(kSource + "/examples/rose.json")});
        drawings.push_back({"leaf.ngc", load_gcode_path(kSource + "/examples/leaf.ngc")});
        drawings.push_back({"star.csv", load_csv_path(kSource + "/examples/star.csv",
                                                      PathBasis::kPolyline, true)});
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_order: %s\n", e.what());
        return 3;
    }
    drawings.push_back({"random " + std::to_string(segments), random_segments(segments)});

    const char* head = markdown
                           ? "| drawing | subpaths | document mm | greedy mm | improved mm | saved "
                             "| order ms | motion s |\n|---|---|---|---|---|---|---|---|\n"
                           : "drawing           subpaths     document mm  greedy mm  improved mm  "
                             "saved  order ms  motion s\n";
    std::fputs(head, stdout);
    int status = 0;
    for (const Drawing& d : drawings) {
        OrderOptions greedy_only;
        greedy_only.improve = false;
        OrderReport g, r;
        (void)order_path(d.path, greedy_only, &g);
        const auto t0 = std::chrono::steady_clock::now();
        const Path ordered = order_path(d.path, {}, &r);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        if (r.travel_after > r.travel_before + 1e-9 || r.travel_after > g.travel_after + 1e-9)
            status = 1;
        std::string motion = "-";
        if (plan && !(quick && d.path.subpaths.size() > 500)) {
            try {
                char text[64];
                std::snprintf(text, sizeof text, "%.2f -> %.2f", motion_seconds(d.path),
                              motion_seconds(ordered));
                motion = text;
            } catch (const std::exception& e) {
                std::fprintf(stderr, "bench_order: %s: %s\n", d.name.c_str(), e.what());
                return 3;
            }
        }
        const double saved =
            r.travel_before > 0 ? 100 * (r.travel_before - r.travel_after) / r.travel_before : 0;
        const std::string counts =
            std::to_string(r.subpaths_before) + " -> " + std::to_string(r.subpaths_after);
        std::printf(markdown ? "| %s | %s | %.1f | %.1f | %.1f | %.0f %% | %.1f | %s |\n"
                             : "%-17s %-12s %11.1f %10.1f %12.1f %5.0f%% %9.1f  %s\n",
                    d.name.c_str(), counts.c_str(), r.travel_before, g.travel_after, r.travel_after,
                    saved, ms, motion.c_str());
    }
    return status;
}
