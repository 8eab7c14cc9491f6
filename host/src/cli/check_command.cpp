#include "check_command.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/work_area.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {

void add_check_command(CLI::App& app, CheckOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "check", "Validate a path file and print a summary: subpaths, spans, length, bounding box");
    add_path_options(*cmd, o.path);
    cmd->add_flag("--json", o.json, "print the summary as one JSON document on standard output");
    cmd->add_option("--machine,-m", o.machine,
                    "machine profile (JSON): its work area serves --fit area")
        ->check(CLI::ExistingFile);
}

namespace {

/// Arc length of a segment: 8-point Gauss-Legendre on each of 8 sub-intervals (exact to
/// ~1e-12 relative for the smooth speed of a cubic). No allocation: check measures every
/// segment of files with millions of points.
double segment_length(const BezierSegment& s) {
    static const double x[4] = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                0.9602898564975363};
    static const double w[4] = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                0.1012285362903763};
    // The control point differences per axis (bezier_d1's, in its order of operations).
    constexpr std::size_t kAxesMax = 8;
    const std::size_t axes = std::min(s.p[0].size(), kAxesMax);
    double d[3][kAxesMax];
    for (std::size_t a = 0; a < axes; ++a) {
        for (int k = 0; k < 3; ++k) d[k][a] = s.p[k + 1][a] - s.p[k][a];
    }
    double total = 0;
    constexpr int kPieces = 8;
    for (int piece = 0; piece < kPieces; ++piece) {
        const double a0 = static_cast<double>(piece) / kPieces, half = 0.5 / kPieces,
                     mid = a0 + half;
        for (int i = 0; i < 4; ++i) {
            for (const double sign : {-1.0, 1.0}) {
                const double u = mid + sign * half * x[i], v = 1 - u;
                double speed = 0;
                for (std::size_t a = 0; a < axes; ++a) {
                    const double c = 3 * (v * v * d[0][a] + 2 * u * v * d[1][a] + u * u * d[2][a]);
                    speed += c * c;
                }
                total += w[i] * half * std::sqrt(speed);
            }
        }
    }
    return total;
}

/// Axis `a` of a segment at u (de Casteljau, exact at u = 0 and 1 as bezier_point).
double coordinate_at(const BezierSegment& s, std::size_t a, double u) {
    const double v = 1 - u;
    const double p = v * s.p[0][a] + u * s.p[1][a], q = v * s.p[1][a] + u * s.p[2][a],
                 r = v * s.p[2][a] + u * s.p[3][a];
    return v * (v * p + u * q) + u * (v * q + u * r);
}

/// Exact per-axis extent of a cubic: its ends and the roots of its derivative in (0, 1).
void extend_box(const BezierSegment& s, std::vector<double>& lo, std::vector<double>& hi) {
    for (std::size_t a = 0; a < lo.size(); ++a) {
        for (double u : extreme_parameters(s, a)) {
            const double v = coordinate_at(s, a, u);
            lo[a] = std::min(lo[a], v);
            hi[a] = std::max(hi[a], v);
        }
    }
}

/// What check reports, measured once for the text and the JSON summary alike.
struct CheckFigures {
    double drawn = 0, travel = 0;  ///< mm
    std::size_t drawing_segments = 0, travel_segments = 0;
    std::vector<double> lo, hi;  ///< bounding box of the drawing, per axis
};

/// Lengths, span counts and the drawing's bounding box of the path's cubics.
CheckFigures measure(const Path& path) {
    CheckFigures f;
    f.lo.assign(path.axes, std::numeric_limits<double>::infinity());
    f.hi.assign(path.axes, -std::numeric_limits<double>::infinity());
    // One segment at a time: a file of 10^6 points makes 10^6 segments, ~300 MB held at once.
    for_each_bezier_segment(path, [&f](const BezierSegment& s) {
        const double length = segment_length(s);
        if (s.pen_down) {
            f.drawn += length;
            ++f.drawing_segments;
            extend_box(s, f.lo, f.hi);
        } else {
            f.travel += length;
            ++f.travel_segments;
        }
    });
    return f;
}

/// "x 1.000 .. 2.000, y 3.000 .. 4.000 mm", or "empty".
std::string box_text(const std::optional<Box2>& box) {
    if (!box) return "empty";
    char text[160];
    std::snprintf(text, sizeof text, "x %.3f .. %.3f, y %.3f .. %.3f mm", box->x_min, box->x_max,
                  box->y_min, box->y_max);
    return text;
}

/// The placement and order lines (only for what ran).
void print_load_report(const LoadedPath& loaded) {
    if (!loaded.gcode_pen.empty()) std::printf("  G-code pen: %s\n", loaded.gcode_pen.c_str());
    if (loaded.placed) {
        std::printf("  placement: %s -> %s (scale %g)\n", box_text(loaded.placement.before).c_str(),
                    box_text(loaded.placement.after).c_str(), loaded.placement.scale);
    }
    if (loaded.ordered) {
        const OrderReport& r = loaded.order;
        const double change =
            r.travel_before > 0 ? 100 * (r.travel_after - r.travel_before) / r.travel_before : 0.0;
        std::printf(
            "  order: pen-up travel from the start %.1f mm -> %.1f mm (%+.0f %%), %zu subpaths -> "
            "%zu "
            "(merged %zu)\n",
            r.travel_before, r.travel_after, change, r.subpaths_before, r.subpaths_after, r.merged);
    } else {
        std::printf("  order: as in the file (%s)\n", loaded.kept_order_because.c_str());
    }
}

/// The human summary (the first 20 subpaths; the rest are counted).
void print_text(const CheckOptions& o, const Path& path, const CheckFigures& f) {
    std::printf("%s: valid, %zu axes, units %s\n", path_display_name(o.path.file).c_str(),
                path.axes, path.units.c_str());
    std::printf("  subpaths: %zu\n", path.subpaths.size());
    for (std::size_t i = 0; i < path.subpaths.size() && i < 20; ++i) {
        const Subpath& sp = path.subpaths[i];
        std::printf("    %zu: %s, %s, %zu points%s\n", i, basis_name(sp.basis),
                    sp.closed ? "closed" : "open", sp.points.size(),
                    sp.feed > 0 ? (", feed " + std::to_string(sp.feed) + " mm/s").c_str() : "");
    }
    if (path.subpaths.size() > 20) std::printf("    ... %zu more\n", path.subpaths.size() - 20);
    std::printf("  spans: %zu drawing, %zu travel\n", f.drawing_segments, f.travel_segments);
    std::printf("  length: %.3f mm drawn, %.3f mm pen-up travel\n", f.drawn, f.travel);
    std::printf("  bounding box (drawing):");
    for (std::size_t a = 0; a < path.axes; ++a) {
        std::printf(" %s %.3f .. %.3f mm%s", axis_column_name(a), f.lo[a], f.hi[a],
                    a + 1 < path.axes ? "," : "\n");
    }
}

/// Every subpath (not only the first 20): basis, closed, point count, feed (null: none).
nlohmann::ordered_json subpaths_json(const Path& path) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const Subpath& sp : path.subpaths) {
        list.push_back(
            {{"basis", basis_name(sp.basis)},
             {"closed", sp.closed},
             {"points", sp.points.size()},
             {"feed_mm_per_s", sp.feed > 0 ? nlohmann::ordered_json(sp.feed) : nullptr}});
    }
    return list;
}

/// {"x": {"min", "max"}, "y": {...}} or null.
nlohmann::ordered_json box_json(const std::optional<Box2>& box) {
    if (!box) return nullptr;
    return {{"x", {{"min", box->x_min}, {"max", box->x_max}}},
            {"y", {{"min", box->y_min}, {"max", box->y_max}}}};
}

/// The summary for machines: the same figures, unrounded (an empty drawing's box is null).
nlohmann::ordered_json summary_json(const CheckOptions& o, const LoadedPath& loaded,
                                    const CheckFigures& f) {
    const Path& path = loaded.path;
    nlohmann::ordered_json box = nlohmann::ordered_json::object();
    for (std::size_t a = 0; a < path.axes; ++a) {
        box[axis_column_name(a)] = {{"min", f.lo[a]}, {"max", f.hi[a]}};
    }
    nlohmann::ordered_json j;
    j["file"] = path_display_name(o.path.file);
    j["valid"] = true;
    j["axes"] = path.axes;
    j["units"] = path.units;
    j["subpath_count"] = path.subpaths.size();
    j["subpaths"] = subpaths_json(path);
    j["drawing_spans"] = f.drawing_segments;
    j["travel_spans"] = f.travel_segments;
    j["drawn_length_mm"] = f.drawn;
    j["travel_length_mm"] = f.travel;
    j["bounding_box_mm"] = box;
    j["placement"] =
        loaded.placed ? nlohmann::ordered_json{{"scale", loaded.placement.scale},
                                               {"box_before_mm", box_json(loaded.placement.before)},
                                               {"box_after_mm", box_json(loaded.placement.after)}}
                      : nlohmann::ordered_json(nullptr);
    j["layers"] = layers_json(path);
    j["pauses"] = count_pauses(path);
    if (!loaded.gcode_pen.empty()) j["gcode_pen"] = loaded.gcode_pen;
    const OrderReport& r = loaded.order;
    j["order"] = loaded.ordered ? nlohmann::ordered_json{{"travel_before_mm", r.travel_before},
                                                         {"travel_after_mm", r.travel_after},
                                                         {"subpaths_before", r.subpaths_before},
                                                         {"subpaths_after", r.subpaths_after},
                                                         {"merged", r.merged}}
                                : nlohmann::ordered_json(nullptr);
    return j;
}

}  // namespace

int run_check(const CheckOptions& o) {
    const std::optional<MachineProfile> machine =
        o.machine.empty() ? std::nullopt
                          : std::optional<MachineProfile>(load_machine_profile(o.machine));
    const LoadedPath loaded = load_path_report(o.path, machine ? &*machine : nullptr);
    if (machine) {
        // What plan and stream would refuse first, checked here too: the axes, then the travel.
        if (machine->axes.size() != loaded.path.axes) {
            throw InputError(o.machine, {},
                             "the machine has " + std::to_string(machine->axes.size()) +
                                 " axes but " + o.path.file + " has " +
                                 std::to_string(loaded.path.axes));
        }
        for_each_bezier_segment(loaded.path, [&](const BezierSegment& s) {
            check_segment_work_area(s, loaded.path, *machine, o.path.file);
        });
    }
    const CheckFigures figures = measure(loaded.path);
    if (o.json) {
        std::cout << summary_json(o, loaded, figures).dump(2) << '\n';
    } else {
        print_text(o, loaded.path, figures);
        print_load_report(loaded);
        const std::string layers = layers_text(loaded.path);
        if (!layers.empty()) std::printf("  %s\n", layers.c_str());
    }
    return 0;
}

}  // namespace pathstream::host
