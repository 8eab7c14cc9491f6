#include "pathstream/host/layers.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <stdexcept>

#include "pathstream/host/geometry.hpp"

namespace pathstream::host {
namespace {

// "1: red, 2: blue" for messages.
std::string layer_list(const Path& path) {
    std::string out;
    for (std::size_t i = 0; i < path.layers.size(); ++i)
        out += (i ? ", " : "") + std::to_string(i + 1) + ": \"" + path.layers[i].name + "\"";
    return out;
}

// The layer a choice names: its name first (a layer may be called "2"), then its number.
std::size_t find_layer(const Path& path, const std::string& choice) {
    for (std::size_t i = 0; i < path.layers.size(); ++i)
        if (path.layers[i].name == choice) return i;
    std::size_t n = 0;
    const bool digits = !choice.empty() && std::all_of(choice.begin(), choice.end(),
                                                       [](char c) { return c >= '0' && c <= '9'; });
    if (digits && choice.size() < 6) n = std::stoul(choice);
    if (n >= 1 && n <= path.layers.size()) return n - 1;
    throw std::invalid_argument(
        "--layer " + choice + ": no such layer (the drawing has " +
        (path.layers.empty() ? std::string("no layers") : layer_list(path)) + ")");
}

// Pen-down length of one subpath (mm): 32 chords per Bezier segment.
double subpath_length(const Subpath& s, std::size_t axes) {
    Path one;
    one.axes = axes;
    one.subpaths.push_back(s);
    one.subpaths.back().pause_before = false;
    double length = 0;
    for (const BezierSegment& b : to_bezier_segments(one)) {
        PathPoint previous = b.p[0];
        for (int k = 1; k <= 32; ++k) {
            const PathPoint p = bezier_point(b, k / 32.0);
            double d = 0;
            for (std::size_t a = 0; a < p.size(); ++a)
                d += (p[a] - previous[a]) * (p[a] - previous[a]);
            length += std::sqrt(d);
            previous = p;
        }
    }
    return length;
}

// A section of the path starts at a pause or a rest: order_sections keeps them in place.
bool starts_section(const Path& path, std::size_t i) {
    const Subpath& s = path.subpaths[i];
    return i == 0 || s.pause_before || s.dwell_before > 0;
}

}  // namespace

Path select_layers(const Path& path, const std::vector<std::string>& chosen) {
    if (chosen.empty()) return path;
    std::vector<bool> keep(std::max<std::size_t>(path.layers.size(), 1), false);
    for (const std::string& c : chosen) keep[find_layer(path, c)] = true;
    Path out = without_subpaths(path);
    for (const Subpath& s : path.subpaths)
        if (keep.at(s.layer)) out.subpaths.push_back(s);
    if (out.subpaths.empty())
        throw std::invalid_argument("--layer: the chosen layers have nothing to draw");
    return out;
}

Path group_by_layer(Path path) {
    if (path.layers.empty()) return path;
    std::stable_sort(path.subpaths.begin(), path.subpaths.end(),
                     [](const Subpath& a, const Subpath& b) { return a.layer < b.layer; });
    return path;
}

void pause_between_layers(Path& path, LayerPause when) {
    if (when == LayerPause::kNone) return;
    for (std::size_t i = 1; i < path.subpaths.size(); ++i) {
        const std::size_t a = path.subpaths[i - 1].layer, b = path.subpaths[i].layer;
        if (a == b) continue;
        if (when == LayerPause::kEveryLayer || a >= path.layers.size() || b >= path.layers.size()) {
            path.subpaths[i].pause_before = true;
            continue;
        }
        const std::string& p = path.layers[a].pen;
        const std::string& q = path.layers[b].pen;
        if (p == "mixed" || q == "mixed" || (!p.empty() && !q.empty() && p != q))
            path.subpaths[i].pause_before = true;
    }
}

void apply_layer_feeds(Path& path, const MachineProfile& machine) {
    for (PathLayer& l : path.layers) {
        for (const auto& [name, feed] : machine.layer_feeds)
            if (name == l.name) l.feed = feed;
    }
    for (Subpath& s : path.subpaths) {
        if (s.feed == 0 && s.layer < path.layers.size()) s.feed = path.layers[s.layer].feed;
    }
}

Path order_sections(Path path, const OrderOptions& options, OrderReport* report) {
    Path out = without_subpaths(path);
    OrderReport total;
    total.subpaths_before = path.subpaths.size();
    total.travel_before = pen_up_travel(path, options.start);
    PathPoint from = options.start;
    for (std::size_t first = 0; first < path.subpaths.size();) {
        std::size_t end = first + 1;
        while (end < path.subpaths.size() && !starts_section(path, end)) ++end;
        Path section = without_subpaths(path);
        // Moved, not copied: each subpath goes into exactly one section.
        section.subpaths.assign(
            std::make_move_iterator(path.subpaths.begin() + static_cast<std::ptrdiff_t>(first)),
            std::make_move_iterator(path.subpaths.begin() + static_cast<std::ptrdiff_t>(end)));
        const bool head_pauses = section.subpaths.front().pause_before;
        const bool head_rests = section.subpaths.front().dwell_before > 0;
        if (head_rests) {
            // A rest belongs to the place it was programmed at: that subpath stays first, as is.
            from = curve_end(section.subpaths.front());
            out.subpaths.push_back(std::move(section.subpaths.front()));
            section.subpaths.erase(section.subpaths.begin());
        }
        if (!section.subpaths.empty()) {
            OrderOptions o = options;
            o.start = from;
            OrderReport r;
            Path ordered = order_path(section, o, &r);
            total.merged += r.merged;
            total.work += r.work;
            for (std::size_t i = 0; i < ordered.subpaths.size(); ++i) {
                Subpath& sp = ordered.subpaths[i];
                sp.pause_before = i == 0 && head_pauses && !head_rests;
                out.subpaths.push_back(std::move(sp));
            }
        }
        from = curve_end(out.subpaths.back());
        first = end;
    }
    total.subpaths_after = out.subpaths.size();
    total.travel_after = pen_up_travel(out, options.start);
    if (report != nullptr) *report = total;
    return out;
}

std::vector<LayerSummary> summarize_layers(const Path& path) {
    std::vector<LayerSummary> out;
    for (const PathLayer& l : path.layers) out.push_back({l.name, 0, 0});
    if (out.empty()) return out;
    for (const Subpath& s : path.subpaths) {
        LayerSummary& l = out.at(s.layer);
        ++l.subpaths;
        l.length += subpath_length(s, path.axes);
    }
    return out;
}

nlohmann::ordered_json layers_json(const Path& path) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    const std::vector<LayerSummary> layers = summarize_layers(path);
    for (std::size_t i = 0; i < layers.size(); ++i) {
        const double feed = path.layers[i].feed;
        out.push_back({{"name", layers[i].name},
                       {"subpaths", layers[i].subpaths},
                       {"drawn_length_mm", layers[i].length},
                       {"feed_mm_s", feed > 0 ? nlohmann::ordered_json(feed)
                                              : nlohmann::ordered_json(nullptr)}});
    }
    return out;
}

std::size_t count_pauses(const Path& path) {
    return static_cast<std::size_t>(std::count_if(path.subpaths.begin(), path.subpaths.end(),
                                                  [](const Subpath& s) { return s.pause_before; }));
}

std::string layers_text(const Path& path) {
    const std::size_t pauses = count_pauses(path);
    if (path.layers.empty() && pauses == 0) return "";
    std::ostringstream out;
    out << std::fixed << std::setprecision(1);
    const std::vector<LayerSummary> layers = summarize_layers(path);
    if (!layers.empty()) {
        out << "layers: " << layers.size() << " (";
        for (std::size_t i = 0; i < layers.size(); ++i) {
            out << (i ? ", " : "") << '"' << layers[i].name << "\" " << layers[i].subpaths
                << (layers[i].subpaths == 1 ? " subpath " : " subpaths ") << layers[i].length
                << " mm";
            if (path.layers[i].feed > 0) out << " at " << path.layers[i].feed << " mm/s";
        }
        out << "), ";
    }
    out << pauses << (pauses == 1 ? " pause" : " pauses") << " for the operator";
    return out.str();
}

}  // namespace pathstream::host
