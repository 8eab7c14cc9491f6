// path.svg, speed.svg, acceleration.svg: drawing and the series behind them.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pathstream/host/plot.hpp"
#include "plot_parts.hpp"
#include "svg_canvas.hpp"

namespace pathstream::host::plot {
namespace {

using detail::add_px;
using detail::axis_name;
using detail::Canvas;
using detail::columns_of;
using detail::decimate_points;
using detail::end_time;
using detail::kMarginBottom;
using detail::kMarginLeft;
using detail::kMarginRight;
using detail::kMarginTop;
using detail::kPenUpDash;
using detail::kTravelDash;
using detail::layer_colour;
using detail::layer_of;
using detail::LegendEntry;
using detail::pen_up_legend;
using detail::shade_pen_up;
using detail::title_of;
using detail::width_of;

/// Point of a cubic Bezier at u (de Casteljau), two coordinates.
Point bezier_xy(const BezierSegment& s, std::size_t ax, std::size_t ay, double u) {
    const auto coord = [&](std::size_t a) {
        const double p0 = s.p[0][a], p1 = s.p[1][a], p2 = s.p[2][a], p3 = s.p[3][a];
        const double q0 = p0 + (p1 - p0) * u, q1 = p1 + (p2 - p1) * u, q2 = p2 + (p3 - p2) * u;
        const double r0 = q0 + (q1 - q0) * u, r1 = q1 + (q2 - q1) * u;
        return r0 + (r1 - r0) * u;
    };
    return {coord(ax), coord(ay)};
}

double polygon_length(const BezierSegment& s, std::size_t ax, std::size_t ay) {
    double len = 0;
    for (int i = 0; i < 3; ++i)
        len += std::hypot(s.p[i + 1][ax] - s.p[i][ax], s.p[i + 1][ay] - s.p[i][ay]);
    return len;
}

struct Bounds {
    double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
    void add(double x, double y) {
        if (!std::isfinite(x) || !std::isfinite(y)) return;
        x0 = std::min(x0, x);
        x1 = std::max(x1, x);
        y0 = std::min(y0, y);
        y1 = std::max(y1, y);
    }
    bool empty() const { return !(x1 >= x0); }
};

/// One axis: position against time for the executed series (and plant).
std::string position_time_svg(const RunRecord& r, const MachineProfile& profile,
                              const Options& options) {
    const double w = width_of(options);
    Canvas c(w, std::round(w * 0.5), kMarginLeft, kMarginTop, kMarginRight, kMarginBottom);
    c.title(title_of(options, "Path (one axis)"));
    const double t_end = end_time(r);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int series = 0; series < (r.has_plant ? 2 : 1); ++series) {
        if (r.bounded[series])
            lo = std::min(lo, r.lo[series][0]), hi = std::max(hi, r.hi[series][0]);
    }
    if (!(hi >= lo)) lo = 0, hi = 1;
    const double pad = std::max(1e-6, (hi - lo) * 0.05);
    c.set_range(0, t_end, lo - pad, hi + pad, false);
    c.axes("time (s)", axis_name(profile, 0) + " (mm)");
    shade_pen_up(c, r);
    std::vector<LegendEntry> legend;
    const auto draw = [&](int series, const std::string& name, const char* id, const char* colour,
                          double width) {
        c.begin_series(id);
        c.polyline(decimate_points(r.position[series], 0, t_end, columns_of(c)), colour, width);
        c.end_group();
        legend.push_back({name, colour, "", width});
    };
    draw(0, r.executed_name, "setpoints", detail::kSetpointColour, 2.5);
    if (r.has_plant) draw(1, r.plant_name, "plant", detail::kPlantColour, 1.2);
    legend.push_back(pen_up_legend());
    c.legend(legend);
    c.note("One axis: position against time (no ideal path drawn). Pen-up time shaded.");
    return c.finish();
}

/// Axes sharing one limit value are drawn as one line (labels would overprint otherwise).
struct LimitGroup {
    double value = 0;
    std::vector<std::size_t> axes;
    std::string names(const MachineProfile& profile, const char* separator) const {
        std::string out;
        for (std::size_t i = 0; i < axes.size(); ++i)
            out += (i ? separator : "") + axis_name(profile, axes[i]);
        return out;
    }
    std::string colour() const { return axes.size() == 1 ? detail::axis_colour(axes[0]) : "#555"; }
};

std::vector<LimitGroup> limit_groups(const MachineProfile& profile, std::size_t axes,
                                     bool acceleration) {
    std::vector<LimitGroup> groups;
    for (std::size_t a = 0; a < axes && a < profile.axes.size(); ++a) {
        const double v =
            acceleration ? profile.axes[a].max_acceleration : profile.axes[a].max_velocity;
        auto it = std::find_if(groups.begin(), groups.end(),
                               [&](const LimitGroup& g) { return g.value == v; });
        if (it == groups.end()) {
            groups.push_back({v, {a}});
        } else {
            it->axes.push_back(a);
        }
    }
    return groups;
}

}  // namespace

Derivatives differentiate(const TickSeries& s, const MachineProfile& profile,
                          unsigned half_window) {
    Derivatives d;
    const std::size_t n = s.ticks(), axes = s.axes;
    const double t = 1.0 / s.tick_hz;
    unsigned h = half_window;
    if (h == 0) {
        h = 1;
        double a_min = std::numeric_limits<double>::infinity();
        for (const AxisLimits& l : profile.axes) {
            if (l.max_acceleration > 0) a_min = std::min(a_min, l.max_acceleration);
        }
        if (s.quantum_mm > 0 && std::isfinite(a_min)) {
            const double seconds = std::sqrt(2 * s.quantum_mm / (0.05 * a_min));
            h = static_cast<unsigned>(std::clamp(std::ceil(seconds / t), 1.0, 64.0));
        }
    }
    if (n >= 3) h = std::min<unsigned>(h, static_cast<unsigned>((n - 1) / 2));
    h = std::max(1u, h);
    d.half_window = h;
    const double ht = h * t;
    d.acceleration_noise = 2 * s.quantum_mm / (ht * ht);
    d.velocity.assign(n * axes, 0.0);
    d.acceleration.assign(n * axes, 0.0);
    d.speed.assign(n, 0.0);
    if (n < 2) return d;
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t lo = k >= h ? k - h : 0, hi = std::min(n - 1, k + h);
        // Acceleration: the nearest k with a full window on both sides.
        const std::size_t kc = n > 2 * h ? std::clamp<std::size_t>(k, h, n - 1 - h) : 0;
        double sq = 0;
        for (std::size_t a = 0; a < axes; ++a) {
            const double v = (s.at(hi, a) - s.at(lo, a)) / (static_cast<double>(hi - lo) * t);
            d.velocity[k * axes + a] = v;
            sq += v * v;
            if (n > 2 * h) {
                d.acceleration[k * axes + a] =
                    (s.at(kc + h, a) - 2 * s.at(kc, a) + s.at(kc - h, a)) / (ht * ht);
            }
        }
        d.speed[k] = std::sqrt(sq);
    }
    return d;
}

std::string path_svg(SegmentSource& path, const RunRecord& r, const MachineProfile& profile,
                     const Options& options) {
    if (r.axes == 1) return position_time_svg(r, profile, options);
    if (r.axes == 0) throw std::invalid_argument("path_svg: the executed series has no axes");
    if (r.xyz) return isometric_path_svg(path, r, profile, options);
    const std::size_t ax = 0, ay = 1;

    // Bounds: the executed series and the ideal path (16 samples per segment suffice).
    Bounds b;
    for (int series = 0; series < (r.has_plant ? 2 : 1); ++series) {
        if (!r.bounded[series]) continue;
        b.add(r.lo[series][0], r.lo[series][1]);
        b.add(r.hi[series][0], r.hi[series][1]);
    }
    BezierSegment seg;
    bool any_segment = false;
    if (!path.rewind()) throw std::invalid_argument("path_svg: the path cannot be read again");
    while (path.next(seg)) {
        any_segment = true;
        if (seg.p[0].size() <= ay) continue;
        for (int i = 0; i <= 16; ++i) {
            const Point p = bezier_xy(seg, ax, ay, i / 16.0);
            b.add(p.x, p.y);
        }
    }
    if (b.empty()) b.add(0, 0);
    double dx = b.x1 - b.x0, dy = b.y1 - b.y0;
    const double extent = std::max({dx, dy, 1e-3});
    dx = std::max(dx, extent * 0.05);
    dy = std::max(dy, extent * 0.05);
    const double pad = 0.04 * std::max(dx, dy);
    dx += 2 * pad;
    dy += 2 * pad;
    const double cx = (b.x0 + b.x1) / 2, cy = (b.y0 + b.y1) / 2;

    // Equal scale on both axes: the plot area takes the data's aspect within [0.4, 1.1] x width.
    const double w = width_of(options);
    const double pw = w - kMarginLeft - kMarginRight;
    const double ph = std::clamp(pw * dy / dx, pw * 0.4, pw * 1.1);
    const double scale = std::min(pw / dx, ph / dy);
    const double hx = pw / scale / 2, hy = ph / scale / 2;
    Canvas c(w, std::round(ph + kMarginTop + kMarginBottom), kMarginLeft, kMarginTop, kMarginRight,
             kMarginBottom);
    c.set_range(cx - hx, cx + hx, cy - hy, cy + hy, !options.y_up);
    c.title(title_of(options, "Path"));
    c.axes(axis_name(profile, ax) + " (mm)",
           axis_name(profile, ay) + (options.y_up ? " (mm), up" : " (mm), down"));

    // Ideal path: consecutive segments of the same pen state form one polyline.
    c.begin_series("ideal-path");
    std::vector<Point> run;
    bool run_down = true;
    std::size_t run_layer = 0;
    const bool layered = !options.layers.empty();
    const auto flush = [&] {
        const std::string colour = layered && run_down ? layer_colour(options, run_layer)
                                                       : std::string(detail::kIdealColour);
        const std::string cls = !run_down ? "pen-up"
                                : layered ? "pen-down layer-" + std::to_string(run_layer + 1)
                                          : "pen-down";
        c.polyline_px(run, colour, run_down ? 5 : 2, run_down ? "" : kTravelDash, cls);
        run.clear();
    };
    if (!path.rewind()) throw std::invalid_argument("path_svg: the path cannot be read again");
    while (path.next(seg)) {
        if (seg.p[0].size() <= ay) continue;
        const std::size_t layer = layer_of(options, seg);
        if (!run.empty() && (seg.pen_down != run_down || (seg.pen_down && layer != run_layer))) {
            const Point joint = run.back();
            flush();
            run.push_back(joint);
        }
        run_down = seg.pen_down;
        run_layer = layer;
        const double len_px = polygon_length(seg, ax, ay) * scale;
        const int samples = static_cast<int>(std::clamp(std::ceil(len_px / 1.5), 2.0, 4000.0));
        for (int i = run.empty() ? 0 : 1; i <= samples; ++i) {
            const Point p = bezier_xy(seg, ax, ay, static_cast<double>(i) / samples);
            add_px(run, {c.px(p.x), c.py(p.y)}, 0.25);
        }
        const Point end = bezier_xy(seg, ax, ay, 1.0);
        const Point end_px{c.px(end.x), c.py(end.y)};
        if (run.back().x != end_px.x || run.back().y != end_px.y) run.push_back(end_px);
    }
    if (!run.empty()) flush();
    c.end_group();

    c.begin_series("setpoints");
    const auto plane = [&c](const TracePoint& t) { return Point{c.px(t.x), c.py(t.y)}; };
    detail::draw_executed(c, r.executed_path, detail::kSetpointColour, 1.6, plane);
    c.end_group();
    std::vector<LegendEntry> legend;
    if (any_segment && layered) {
        for (std::size_t l = 0; l < options.layers.size(); ++l)
            legend.push_back({"layer " + options.layers[l], layer_colour(options, l), "", 5});
        legend.push_back({"ideal travel (pen up)", detail::kIdealColour, kTravelDash, 2});
    } else if (any_segment) {
        legend.push_back({"ideal path", detail::kIdealColour, "", 5});
        legend.push_back({"ideal travel (pen up)", detail::kIdealColour, kTravelDash, 2});
    }
    legend.push_back({r.executed_name.empty() ? "setpoints" : r.executed_name,
                      detail::kSetpointColour, "", 1.6});
    if (r.has_plant) {
        c.begin_series("plant");
        detail::draw_executed(c, r.plant_path, detail::kPlantColour, 1, plane);
        c.end_group();
        legend.push_back(
            {r.plant_name.empty() ? "plant" : r.plant_name, detail::kPlantColour, "", 1});
    }
    c.legend(legend);
    std::string note =
        "Equal scale; +" + axis_name(profile, ay) +
        (options.y_up ? " points up." : " points down (SVG / plotter coordinates).") +
        " Executed pen-up moves dashed.";
    if (r.axes > 2)
        note += " Axes " + axis_name(profile, ax) + ", " + axis_name(profile, ay) + " of " +
                std::to_string(r.axes) + ".";
    c.note(note);
    return c.finish();
}

std::string speed_svg(const RunRecord& r, const MachineProfile& profile, const Options& options) {
    const double w = width_of(options);
    Canvas c(w, std::round(w * 0.5), kMarginLeft, kMarginTop, kMarginRight, kMarginBottom);
    c.title(title_of(options, "Path speed"));
    const double t_end = end_time(r);
    double top = std::max(profile.feed, profile.travel_feed);
    top = std::max(top, r.figures.peak_speed);
    for (const AxisLimits& l : profile.axes) top = std::max(top, l.max_velocity);
    c.set_range(0, t_end, 0, std::max(top, 1e-6) * 1.08, false);
    c.axes("time (s)", "speed (mm/s)");
    shade_pen_up(c, r);
    const std::vector<LimitGroup> limits = limit_groups(profile, r.axes, false);
    c.body() << "<g id=\"velocity-limits\">\n";
    for (const LimitGroup& g : limits) {
        c.hline(g.value, g.colour(), "4 3", "velocity-limit-" + g.names(profile, "-"),
                g.names(profile, ", ") + " limit " + detail::format_number(g.value, 0) + " mm/s");
    }
    c.body() << "</g>\n";
    c.hline(profile.feed, detail::kFeedColour, "", "feed",
            "feed " + detail::format_number(profile.feed, 0) + " mm/s");
    c.hline(profile.travel_feed, detail::kFeedColour, "2 3", "travel-feed",
            "travel feed " + detail::format_number(profile.travel_feed, 0) + " mm/s");
    c.begin_series("speed");
    c.polyline(decimate_points(r.speed, 0, t_end, columns_of(c)), "#000", 1.3);
    c.end_group();
    std::vector<LegendEntry> legend = {{"path speed", "#000", "", 1.5},
                                       {"feed", detail::kFeedColour, "", 1.5},
                                       {"travel feed", detail::kFeedColour, "2 3", 1.5}};
    for (const LimitGroup& g : limits)
        legend.push_back({g.names(profile, ", ") + " limit", g.colour(), "4 3", 1.5});
    legend.push_back(pen_up_legend());
    c.legend(legend);
    c.note("Speed = |v| of the " + r.executed_name +
           " over all axes, central differences over +/-" + std::to_string(r.figures.half_window) +
           " tick(s); pen-up time shaded. An axis limit bounds that axis' own speed, not |v|.");
    return c.finish();
}

std::string acceleration_svg(const RunRecord& r, const MachineProfile& profile,
                             const Options& options) {
    const double w = width_of(options);
    Canvas c(w, std::round(w * 0.55), kMarginLeft, kMarginTop, kMarginRight, kMarginBottom);
    c.title(title_of(options, "Axis acceleration"));
    const double t_end = end_time(r);
    double top = 0;
    for (double a : r.figures.peak_acceleration) top = std::max(top, a);
    for (std::size_t a = 0; a < r.axes && a < profile.axes.size(); ++a) {
        top = std::max(top, profile.axes[a].max_acceleration);
    }
    top = std::max(top, 1e-6) * 1.08;
    c.set_range(0, t_end, -top, top, false);
    c.axes("time (s)", "acceleration (mm/s\xc2\xb2)");
    shade_pen_up(c, r);
    c.body() << "<g id=\"acceleration-limits\">\n";
    for (const LimitGroup& g : limit_groups(profile, r.axes, true)) {
        const std::string id = "acceleration-limit-" + g.names(profile, "-"),
                          names = g.names(profile, ", ");
        c.hline(g.value, g.colour(), "4 3", id, names + " +" + detail::format_number(g.value, 0));
        c.hline(-g.value, g.colour(), "4 3", id + "-negative",
                names + " \xe2\x88\x92" + detail::format_number(g.value, 0));
    }
    c.body() << "</g>\n";
    std::vector<LegendEntry> legend;
    for (std::size_t a = 0; a < r.axes; ++a) {
        const std::string name = axis_name(profile, a);
        c.begin_series("acceleration-" + name);
        c.polyline(decimate_points(r.acceleration.at(a), 0, t_end, columns_of(c)),
                   detail::axis_colour(a), 1.2);
        c.end_group();
        legend.push_back({name, detail::axis_colour(a), "", 1.5});
    }
    legend.push_back({"limits", "#555", "4 3", 1.5});
    legend.push_back(pen_up_legend());
    c.legend(legend);
    c.note("Second differences of the " + r.executed_name + " over +/-" +
           std::to_string(r.figures.half_window) + " tick(s): rounding noise up to " +
           detail::format_number(r.figures.acceleration_noise, 0) +
           " mm/s\xc2\xb2. Pen-up time shaded.");
    return c.finish();
}

std::string path_svg(const std::vector<BezierSegment>& path, const TickSeries& executed,
                     const TickSeries* plant, const MachineProfile& profile,
                     const Options& options) {
    if (executed.axes == 0)
        throw std::invalid_argument("path_svg: the executed series has no axes");
    VectorSegmentSource source(path);
    return path_svg(source, record_of(executed, plant, profile, options.half_window_ticks), profile,
                    options);
}

std::string speed_svg(const TickSeries& executed, const MachineProfile& profile,
                      const Options& options) {
    return speed_svg(record_of(executed, nullptr, profile, options.half_window_ticks), profile,
                     options);
}

std::string acceleration_svg(const TickSeries& executed, const MachineProfile& profile,
                             const Options& options) {
    return acceleration_svg(record_of(executed, nullptr, profile, options.half_window_ticks),
                            profile, options);
}

}  // namespace pathstream::host::plot
