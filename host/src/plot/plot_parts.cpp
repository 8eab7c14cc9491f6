// Pieces the plot writers share (plot_parts.hpp): axis names, pen-up shading, min/max
// decimation, sizes, layer colours.
#include "plot_parts.hpp"

#include <algorithm>
#include <cmath>

namespace pathstream::host::plot {
namespace {

/// decimate_min_max over `n` samples (x(i), y(i)).
template <typename X, typename Y>
std::vector<Point> decimate(std::size_t n, X x, Y y, double x_min, double x_max,
                            std::size_t columns) {
    std::vector<Point> out;
    if (n <= 2 * columns || columns == 0 || !(x_max > x_min)) {
        out.reserve(n);
        for (std::size_t i = 0; i < n; ++i) {
            if (!std::isnan(y(i))) out.push_back({x(i), y(i)});
        }
        return out;
    }
    out.reserve(2 * columns + 2);
    const double scale = static_cast<double>(columns) / (x_max - x_min);
    std::size_t i = 0;
    const auto emit = [&](std::size_t idx) {
        if (out.empty() || out.back().x != x(idx) || out.back().y != y(idx))
            out.push_back({x(idx), y(idx)});
    };
    // The first sample always (even a NaN-free start is what a reader expects at t = 0).
    while (i < n && std::isnan(y(i))) ++i;
    if (i == n) return out;
    const std::size_t first = i;
    std::size_t last = first;
    emit(first);
    while (i < n) {
        const double cx = std::floor((x(i) - x_min) * scale);
        std::size_t lo = n, hi = n;
        for (; i < n && std::floor((x(i) - x_min) * scale) == cx; ++i) {
            if (std::isnan(y(i))) continue;
            if (lo == n || y(i) < y(lo)) lo = i;
            if (hi == n || y(i) > y(hi)) hi = i;
            last = i;
        }
        if (lo == n) continue;
        if (lo <= hi) {
            emit(lo);
            emit(hi);
        } else {
            emit(hi);
            emit(lo);
        }
    }
    emit(last);
    return out;
}

}  // namespace

std::vector<Point> decimate_min_max(const std::vector<double>& x, const std::vector<double>& y,
                                    double x_min, double x_max, std::size_t columns) {
    return decimate(
        std::min(x.size(), y.size()), [&](std::size_t i) { return x[i]; },
        [&](std::size_t i) { return y[i]; }, x_min, x_max, columns);
}

namespace detail {

std::string axis_name(const MachineProfile& profile, std::size_t axis) {
    if (axis < profile.axes.size() && !profile.axes[axis].name.empty())
        return profile.axes[axis].name;
    static const char* const names[] = {"x", "y", "z", "a", "b", "c", "u", "v"};
    return axis < 8 ? names[axis] : "axis " + std::to_string(axis);
}

void add_px(std::vector<Point>& run, Point p, double min_px) {
    if (!run.empty() && std::hypot(p.x - run.back().x, p.y - run.back().y) < min_px) return;
    run.push_back(p);
}

void draw_executed(Canvas& c, const std::vector<TracePoint>& s, const std::string& colour,
                   double width, const std::function<Point(const TracePoint&)>& to_px) {
    const std::size_t n = s.size();
    std::size_t k = 0;
    while (k < n) {
        const bool down = s[k].pen_down;
        std::vector<Point> run;
        std::size_t j = k;
        for (; j < n && s[j].pen_down == down; ++j) add_px(run, to_px(s[j]), 0.75);
        const std::size_t last = j < n ? j : n - 1;  // share the boundary point with the next run
        const Point end = to_px(s[last]);
        if (run.empty() || run.back().x != end.x || run.back().y != end.y) run.push_back(end);
        c.polyline_px(run, colour, width, down ? "" : kPenUpDash, down ? "pen-down" : "pen-up");
        k = j;
    }
}

LegendEntry pen_up_legend() {
    return {"pen up", kPenUpShade, "", 10};
}

void shade_pen_up(Canvas& c, const RunRecord& r) {
    const double t = 1.0 / r.tick_hz;
    const double merge = 1.0 / std::max(1e-12, c.px(1) - c.px(0));  // one pixel in seconds
    double from = -1, to = -1;
    c.body() << "<g id=\"pen-up-intervals\">\n";
    for (const auto& [first, end] : r.pen_up) {
        const double a = static_cast<double>(first) * t;
        const double b = static_cast<double>(end - 1) * t + t;
        if (from >= 0 && a - to <= merge) {
            to = b;
            continue;
        }
        if (from >= 0) c.band(from, to, kPenUpShade, "pen-up");
        from = a;
        to = b;
    }
    if (from >= 0) c.band(from, to, kPenUpShade, "pen-up");
    c.body() << "</g>\n";
}

std::vector<Point> decimate_points(const std::vector<Point>& points, double x_min, double x_max,
                                   std::size_t columns) {
    return decimate(
        points.size(), [&](std::size_t i) { return points[i].x; },
        [&](std::size_t i) { return points[i].y; }, x_min, x_max, columns);
}

double end_time(const RunRecord& r) {
    const std::uint64_t n = r.figures.ticks;
    return n > 1 ? static_cast<double>(n - 1) / r.tick_hz : 1;
}

std::string title_of(const Options& o, const std::string& what) {
    return o.title.empty() ? what : what + " \xe2\x80\x94 " + o.title;
}

double width_of(const Options& o) {
    return std::max(400.0, static_cast<double>(o.width_px));
}

std::size_t columns_of(const Canvas& c) {
    return static_cast<std::size_t>(std::max(50.0, std::ceil(c.plot_width())));
}

// The palette reads on white and differs from the setpoints' colour.
std::string layer_colour(const Options& o, std::size_t layer) {
    const std::string& name = o.layers.at(layer);
    if (name.size() == 7 && name[0] == '#' &&
        name.find_first_not_of("0123456789abcdefABCDEF", 1) == std::string::npos) {
        return name;
    }
    static const char* const kPalette[] = {"#1b9e77", "#d95f02", "#7570b3",
                                           "#e7298a", "#66a61e", "#e6ab02"};
    return kPalette[layer % 6];
}

std::size_t layer_of(const Options& o, const BezierSegment& s) {
    return s.subpath < o.subpath_layers.size() ? o.subpath_layers[s.subpath] : 0;
}

}  // namespace detail
}  // namespace pathstream::host::plot
