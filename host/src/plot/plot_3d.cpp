// path.svg in 3-D (the isometric view), for a machine with x, y and z axes: a router's cuts and
// rapids cannot be told apart in a top view, where a plunge is a dot.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pathstream/host/isometric.hpp"
#include "pathstream/host/plot.hpp"
#include "plot_parts.hpp"
#include "svg_canvas.hpp"

namespace pathstream::host::plot {
namespace {

using detail::add_px;
using detail::axis_name;
using detail::Canvas;
using detail::format_number;
using detail::kMarginBottom;
using detail::kMarginLeft;
using detail::kMarginRight;
using detail::kMarginTop;
using detail::LegendEntry;
using detail::xml_escape;

struct Vec3 {
    double x = 0, y = 0, z = 0;
};

/// A segment's point at u (de Casteljau) on the axes x, y, z.
Vec3 bezier_xyz(const BezierSegment& s, const XyzAxes& a, double u) {
    const auto coord = [&](std::size_t i) {
        const double p0 = s.p[0][i], p1 = s.p[1][i], p2 = s.p[2][i], p3 = s.p[3][i];
        const double q0 = p0 + (p1 - p0) * u, q1 = p1 + (p2 - p1) * u, q2 = p2 + (p3 - p2) * u;
        const double r0 = q0 + (q1 - q0) * u, r1 = q1 + (q2 - q1) * u;
        return r0 + (r1 - r0) * u;
    };
    return {coord(a.x), coord(a.y), coord(a.z)};
}

/// Length of the control polygon: at least the curve's, and so at least its view's.
double polygon_length(const BezierSegment& s, const XyzAxes& a) {
    double len = 0;
    for (int i = 0; i < 3; ++i) {
        len += std::hypot(s.p[i + 1][a.x] - s.p[i][a.x], s.p[i + 1][a.y] - s.p[i][a.y],
                          s.p[i + 1][a.z] - s.p[i][a.z]);
    }
    return len;
}

struct Box3 {
    static constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo[3] = {kInf, kInf, kInf};
    double hi[3] = {-kInf, -kInf, -kInf};
    void add(const Vec3& p) {
        const double v[3] = {p.x, p.y, p.z};
        if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) return;
        for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], v[i]), hi[i] = std::max(hi[i], v[i]);
    }
    bool empty() const { return !(hi[0] >= lo[0]); }
    Vec3 corner(int k) const {
        return {k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]};
    }
};

/// Where a point of the machine lands on the canvas: isometric(), then the canvas's mapping.
Point to_px(const Canvas& c, const Vec3& p) {
    const IsometricPoint q = isometric(p.x, p.y, p.z);
    return {c.px(q.right), c.py(q.up)};
}

/// The largest 1, 2 or 5 x 10^n at most `target` (> 0).
double nice_length(double target) {
    const double m = std::pow(10.0, std::floor(std::log10(target)));
    for (double k : {5.0, 2.0}) {
        if (k * m <= target) return k * m;
    }
    return m;
}

/// An arrow from `from` to `to` (pixels) with its head, and `label` beyond its tip.
void arrow(Canvas& c, Point from, Point to, const std::string& colour, const std::string& label) {
    const double len = std::max(1e-9, std::hypot(to.x - from.x, to.y - from.y));
    const double dx = (to.x - from.x) / len, dy = (to.y - from.y) / len;
    c.polyline_px({from, to}, colour, 1.6, "", "axis-arrow");
    c.polyline_px({{to.x - 9 * dx + 4 * dy, to.y - 9 * dy - 4 * dx},
                   to,
                   {to.x - 9 * dx - 4 * dy, to.y - 9 * dy + 4 * dx}},
                  colour, 1.6, "", "arrow-head");
    c.body() << "<text class=\"axis-label\" x=\"" << format_number(to.x + 12 * dx, 1) << "\" y=\""
             << format_number(to.y + 12 * dy + 4, 1) << "\" text-anchor=\"middle\" fill=\""
             << colour << "\" font-weight=\"bold\">" << xml_escape(label) << "</text>\n";
}

}  // namespace

std::string isometric_path_svg(SegmentSource& path, const RunRecord& r,
                               const MachineProfile& profile, const Options& options) {
    if (!r.xyz)
        throw std::invalid_argument("isometric_path_svg: the machine has no x, y and z axes");
    const XyzAxes a = *r.xyz;
    const std::size_t needed = std::max({a.x, a.y, a.z}) + 1;

    // The box of the motion and of the ideal path (16 samples per segment suffice).
    Box3 box;
    for (int series = 0; series < (r.has_plant ? 2 : 1); ++series) {
        if (!r.bounded[series]) continue;
        box.add({r.lo[series][0], r.lo[series][1], r.lo[series][2]});
        box.add({r.hi[series][0], r.hi[series][1], r.hi[series][2]});
    }
    BezierSegment seg;
    bool any_segment = false;
    if (!path.rewind()) throw std::invalid_argument("path_svg: the path cannot be read again");
    while (path.next(seg)) {
        any_segment = true;
        if (seg.p[0].size() < needed) continue;
        for (int i = 0; i <= 16; ++i) box.add(bezier_xyz(seg, a, i / 16.0));
    }
    if (box.empty()) box.add({0, 0, 0});
    const double extent =
        std::max({box.hi[0] - box.lo[0], box.hi[1] - box.lo[1], box.hi[2] - box.lo[2], 1e-3});
    // The arrows and the scale bar: one nice length at most a quarter of the largest extent,
    // outside the box where the view has nothing else: the arrows left of its leftmost corner
    // (the low one: towards -x and -y, which the view puts straight left), the bar upright
    // right of its rightmost corner (towards +x and +y).
    const double unit = nice_length(extent / 4), off = 0.12 * extent;
    const Vec3 origin = {box.lo[0] - off, box.lo[1] - off, box.lo[2]};
    const Vec3 tips[3] = {{origin.x + unit, origin.y, origin.z},
                          {origin.x, origin.y + unit, origin.z},
                          {origin.x, origin.y, origin.z + unit}};
    const Vec3 bar[2] = {{box.hi[0] + off, box.hi[1] + off, box.lo[2]},
                         {box.hi[0] + off, box.hi[1] + off, box.lo[2] + unit}};

    // Equal scale: the view's extent, padded, in a plot area of its aspect within [0.4, 1.1] x
    // width.
    double u0 = std::numeric_limits<double>::infinity(), u1 = -u0, v0 = u0, v1 = -u0;
    const auto grow = [&](const Vec3& p) {
        const IsometricPoint q = isometric(p.x, p.y, p.z);
        u0 = std::min(u0, q.right), u1 = std::max(u1, q.right);
        v0 = std::min(v0, q.up), v1 = std::max(v1, q.up);
    };
    for (int k = 0; k < 8; ++k) grow(box.corner(k));
    for (const Vec3& p : tips) grow(p);
    grow(bar[0]), grow(bar[1]);
    const double pad = 0.06 * std::max(u1 - u0, v1 - v0);
    const double du = u1 - u0 + 2 * pad, dv = v1 - v0 + 2 * pad;
    const double w = detail::width_of(options);
    const double pw = w - kMarginLeft - kMarginRight;
    const double ph = std::clamp(pw * dv / du, pw * 0.4, pw * 1.1);
    const double scale = std::min(pw / du, ph / dv);
    const double hu = pw / scale / 2, hv = ph / scale / 2, cu = (u0 + u1) / 2, cv = (v0 + v1) / 2;
    Canvas c(w, std::round(ph + kMarginTop + kMarginBottom), kMarginLeft, kMarginTop, kMarginRight,
             kMarginBottom);
    c.set_range(cu - hu, cu + hu, cv - hv, cv + hv, false);
    c.title(detail::title_of(options, "Path (isometric)"));

    c.begin_series("bounding-box");
    for (int k = 0; k < 8; ++k) {
        for (int bit : {1, 2, 4}) {
            if (k & bit) continue;  // each edge once, from its lower end
            c.polyline_px({to_px(c, box.corner(k)), to_px(c, box.corner(k | bit))}, "#d0d0d0", 0.8,
                          "", "box-edge");
        }
    }
    c.end_group();

    // The ideal path: consecutive segments of the same pen state (and layer) form one polyline.
    c.begin_series("ideal-path");
    const bool layered = !options.layers.empty();
    std::vector<Point> run;
    bool run_down = true;
    std::size_t run_layer = 0;
    const auto flush = [&] {
        const std::string colour = layered && run_down ? detail::layer_colour(options, run_layer)
                                                       : std::string(detail::kIdealColour);
        const std::string cls = !run_down ? "pen-up"
                                : layered ? "pen-down layer-" + std::to_string(run_layer + 1)
                                          : "pen-down";
        c.polyline_px(run, colour, run_down ? 5 : 2, run_down ? "" : detail::kTravelDash, cls);
        run.clear();
    };
    if (!path.rewind()) throw std::invalid_argument("path_svg: the path cannot be read again");
    while (path.next(seg)) {
        if (seg.p[0].size() < needed) continue;
        const std::size_t layer = detail::layer_of(options, seg);
        if (!run.empty() && (seg.pen_down != run_down || (seg.pen_down && layer != run_layer))) {
            const Point joint = run.back();
            flush();
            run.push_back(joint);
        }
        run_down = seg.pen_down;
        run_layer = layer;
        const double len_px = polygon_length(seg, a) * scale;
        const int samples = static_cast<int>(std::clamp(std::ceil(len_px / 1.5), 2.0, 4000.0));
        for (int i = run.empty() ? 0 : 1; i <= samples; ++i)
            add_px(run, to_px(c, bezier_xyz(seg, a, static_cast<double>(i) / samples)), 0.25);
        const Point end = to_px(c, bezier_xyz(seg, a, 1.0));
        if (run.back().x != end.x || run.back().y != end.y) run.push_back(end);
    }
    if (!run.empty()) flush();
    c.end_group();

    c.begin_series("setpoints");
    const auto view = [&c](const TracePoint& t) { return to_px(c, {t.x, t.y, t.z}); };
    detail::draw_executed(c, r.executed_path, detail::kSetpointColour, 1.6, view);
    c.end_group();
    if (r.has_plant) {
        c.begin_series("plant");
        detail::draw_executed(c, r.plant_path, detail::kPlantColour, 1, view);
        c.end_group();
    }

    c.begin_series("axis-arrows");
    const std::size_t axis_of[3] = {a.x, a.y, a.z};
    for (int i = 0; i < 3; ++i)
        arrow(c, to_px(c, origin), to_px(c, tips[i]), "#444", axis_name(profile, axis_of[i]));
    c.end_group();
    c.begin_series("scale");
    const Point b0 = to_px(c, bar[0]), b1 = to_px(c, bar[1]);
    c.polyline_px({b0, b1}, "#000", 1.2, "", "scale-bar");
    for (const Point& e : {b0, b1})
        c.polyline_px({{e.x - 5, e.y}, {e.x + 5, e.y}}, "#000", 1.2, "", "scale-tick");
    // Left of the bar: the view's right edge may be near.
    c.body() << "<text class=\"scale-label\" x=\"" << format_number(b0.x - 8, 1) << "\" y=\""
             << format_number((b0.y + b1.y) / 2 + 4, 1) << "\" text-anchor=\"end\" fill=\"#000\">"
             << format_number(unit, unit < 1 ? 3 : 0) << " mm</text>\n";
    c.end_group();

    std::vector<LegendEntry> legend;
    if (any_segment && layered) {
        for (std::size_t l = 0; l < options.layers.size(); ++l)
            legend.push_back(
                {"layer " + options.layers[l], detail::layer_colour(options, l), "", 5});
    } else if (any_segment) {
        legend.push_back({"ideal path (feed)", detail::kIdealColour, "", 5});
    }
    if (any_segment)
        legend.push_back({"ideal rapids (pen up)", detail::kIdealColour, detail::kTravelDash, 2});
    legend.push_back({r.executed_name.empty() ? "setpoints" : r.executed_name,
                      detail::kSetpointColour, "", 1.6});
    if (r.has_plant)
        legend.push_back(
            {r.plant_name.empty() ? "plant" : r.plant_name, detail::kPlantColour, "", 1});
    c.legend(legend);
    const std::string x = axis_name(profile, a.x), y = axis_name(profile, a.y),
                      z = axis_name(profile, a.z);
    const auto range = [&](int i) {
        return format_number(box.lo[i], 1) + " .. " + format_number(box.hi[i], 1);
    };
    c.note("Isometric view from +" + x + ", -" + y + ", +" + z + ": right = (" + x + " + " + y +
           ") cos 30\xc2\xb0, up = " + z + " + (" + y + " - " + x +
           ")/2, so a mm along any axis is a mm on the plot; arrows and scale bar " +
           format_number(unit, unit < 1 ? 3 : 0) +
           " mm. Feed (pen down) solid, rapids (pen up) dashed. Box: " + x + " " + range(0) + ", " +
           y + " " + range(1) + ", " + z + " " + range(2) + " mm.");
    return c.finish();
}

}  // namespace pathstream::host::plot
