// Placement: one affine map of x and y built from the options, applied to every control point.
#include "pathstream/host/placement.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"

namespace pathstream::host {
namespace {

/// x' = a x + b y + e, y' = c x + d y + f.
struct Affine {
    double a = 1, b = 0, c = 0, d = 1, e = 0, f = 0;
    /// This map followed by `next`.
    Affine then(const Affine& n) const {
        return {n.a * a + n.b * c, n.a * b + n.b * d,       n.c * a + n.d * c,
                n.c * b + n.d * d, n.a * e + n.b * f + n.e, n.c * e + n.d * f + n.f};
    }
    void apply(double& x, double& y) const {
        const double nx = a * x + b * y + e, ny = c * x + d * y + f;
        x = nx, y = ny;
    }
    /// Image of an axis-aligned box; exact here because every map placement builds is a
    /// quarter-turn rotation, a flip, a positive scale or a shift.
    Box2 apply(const Box2& box) const {
        double x0 = box.x_min, y0 = box.y_min, x1 = box.x_max, y1 = box.y_max;
        apply(x0, y0);
        apply(x1, y1);
        return {std::min(x0, x1), std::min(y0, y1), std::max(x0, x1), std::max(y0, y1)};
    }
};

/// Extends the box by a cubic's exact extent: its ends and the roots of its derivative.
void extend(const BezierSegment& s, Box2& box) {
    for (std::size_t axis = 0; axis < 2; ++axis) {
        for (double u : extreme_parameters(s, axis)) {
            const double v = bezier_point(s, u)[axis];
            double& lo = axis == 0 ? box.x_min : box.y_min;
            double& hi = axis == 0 ? box.x_max : box.y_max;
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    }
}

/// Fraction (0 low edge, 0.5 middle, 1 high edge) of the box in x and y for an alignment.
std::array<double, 2> anchor(const std::string& align, bool y_down) {
    static const char* const kNames[] = {"center", "top-left",    "top",    "top-right",   "left",
                                         "right",  "bottom-left", "bottom", "bottom-right"};
    bool known = false;
    for (const char* n : kNames) known = known || align == n;
    if (!known) {
        throw std::invalid_argument(
            "--align: \"" + align +
            "\" is not one of center, top-left, top, top-right, left, right, "
            "bottom-left, bottom, bottom-right");
    }
    const double fx = align.find("left") != std::string::npos    ? 0
                      : align.find("right") != std::string::npos ? 1
                                                                 : 0.5;
    double fy = 0.5;
    if (align.rfind("top", 0) == 0) fy = y_down ? 0 : 1;
    if (align.rfind("bottom", 0) == 0) fy = y_down ? 1 : 0;
    return {fx, fy};
}

}  // namespace

std::optional<Box2> drawing_box(const Path& path) {
    if (path.axes < 2) return std::nullopt;
    std::optional<Box2> box;
    for (const BezierSegment& s : to_bezier_segments(path)) {
        if (!s.pen_down) continue;
        if (!box) box = Box2{s.p[0][0], s.p[0][1], s.p[0][0], s.p[0][1]};
        extend(s, *box);
    }
    return box;
}

std::optional<Box2> work_area(const MachineProfile& profile) {
    if (profile.axes.size() < 2 || !profile.axes[0].has_travel || !profile.axes[1].has_travel)
        return std::nullopt;
    return Box2{profile.axes[0].travel_min, profile.axes[1].travel_min, profile.axes[0].travel_max,
                profile.axes[1].travel_max};
}

Box2 paper_box(const std::string& name) {
    struct Paper {
        const char* name;
        double width, height;
    };
    static const Paper kPapers[] = {{"a0", 841, 1189},       {"a1", 594, 841},
                                    {"a2", 420, 594},        {"a3", 297, 420},
                                    {"a4", 210, 297},        {"a5", 148, 210},
                                    {"a6", 105, 148},        {"letter", 215.9, 279.4},
                                    {"legal", 215.9, 355.6}, {"tabloid", 279.4, 431.8}};
    const std::string suffix = "-landscape";
    const bool landscape = name.size() > suffix.size() &&
                           name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0;
    const std::string base = landscape ? name.substr(0, name.size() - suffix.size()) : name;
    for (const Paper& p : kPapers) {
        if (base == p.name)
            return landscape ? Box2{0, 0, p.height, p.width} : Box2{0, 0, p.width, p.height};
    }
    throw std::invalid_argument(
        "--fit: \"" + name +
        "\" is not area or a paper: a0, a1, a2, a3, a4, a5, a6, letter, legal, "
        "tabloid (add -landscape for the long side along x)");
}

namespace {

bool box_inside(const Box2& inner, const Box2& outer) {
    constexpr double kSlack = 1e-9;  // mm: a paper exactly as large as the travel fits
    return inner.x_min >= outer.x_min - kSlack && inner.y_min >= outer.y_min - kSlack &&
           inner.x_max <= outer.x_max + kSlack && inner.y_max <= outer.y_max + kSlack;
}

std::string mm_size(const Box2& b) {
    char text[64];
    std::snprintf(text, sizeof text, "%g x %g mm", b.width(), b.height());
    return text;
}

std::string mm_corner(const Box2& b) {
    char text[64];
    std::snprintf(text, sizeof text, "(%g, %g) mm", b.x_min, b.y_min);
    return text;
}

}  // namespace

Path place_path(const Path& path, const PlacementOptions& o, const std::optional<Box2>& area,
                PlacementReport* report) {
    PlacementReport r;
    if (!o.active()) {
        if (report != nullptr) *report = r;
        return path;
    }
    if (path.axes < 2) throw std::invalid_argument("placement needs x and y: the path has 1 axis");
    if (o.rotate != 0 && o.rotate != 90 && o.rotate != 180 && o.rotate != 270) {
        throw std::invalid_argument("--rotate: " + std::to_string(o.rotate) +
                                    " is not 90, 180 or 270");
    }
    if (!(o.scale >= 0) || !std::isfinite(o.scale))
        throw std::invalid_argument("--scale: must be a positive number");
    if (o.scale != 0 && !o.fit.empty())
        throw std::invalid_argument("--scale and --fit exclude each other");
    if (!(o.margin >= 0) || !std::isfinite(o.margin))
        throw std::invalid_argument("--margin: must be 0 or more mm");
    if (o.margin != 0 && o.fit.empty())
        throw std::invalid_argument("--margin applies only with --fit");
    if (o.origin != "top-left" && o.origin != "bottom-left") {
        throw std::invalid_argument("--origin: \"" + o.origin +
                                    "\" is not top-left or bottom-left");
    }
    if (o.translate &&
        (!std::isfinite(o.translate->first) || !std::isfinite(o.translate->second))) {
        throw std::invalid_argument("--translate: coordinates must be finite");
    }
    r.before = drawing_box(path);

    Affine m;
    if (o.rotate == 90) m = {0, -1, 1, 0, 0, 0};
    if (o.rotate == 180) m = {-1, 0, 0, -1, 0, 0};
    if (o.rotate == 270) m = {0, 1, -1, 0, 0, 0};
    if (o.flip_y) m = m.then({1, 0, 0, -1, 0, 0});
    std::optional<Box2> target;
    if (!o.fit.empty()) {
        if (o.fit == "area") {
            if (!area) {
                throw std::invalid_argument(
                    "--fit area needs a machine profile (--machine) whose x and y axes have a "
                    "\"travel\" range");
            }
            target = area;
        } else {
            target = paper_box(o.fit);
            if (area && !box_inside(*target, *area)) {
                // The paper lies on the machine from its origin: name the orientation that fits.
                const bool landscape =
                    o.fit.size() > 10 && o.fit.compare(o.fit.size() - 10, 10, "-landscape") == 0;
                const std::string other =
                    landscape ? o.fit.substr(0, o.fit.size() - 10) : o.fit + "-landscape";
                const bool other_fits = box_inside(paper_box(other), *area);
                throw std::invalid_argument(
                    "--fit " + o.fit + ": the paper (" + mm_size(*target) +
                    ") does not fit the machine's work area (" + mm_size(*area) + " from " +
                    mm_corner(*area) + ")" +
                    (other_fits ? "; --fit " + other + " does" : ", in either orientation"));
            }
        }
        target->x_min += o.margin, target->y_min += o.margin;
        target->x_max -= o.margin, target->y_max -= o.margin;
        if (area && o.edge_clearance > 0) {
            // The planner's path may run up to its chord tolerance off the drawing: a fit that
            // reaches the travel's edge keeps that much inside it.
            target->x_min = std::max(target->x_min, area->x_min + o.edge_clearance);
            target->y_min = std::max(target->y_min, area->y_min + o.edge_clearance);
            target->x_max = std::min(target->x_max, area->x_max - o.edge_clearance);
            target->y_max = std::min(target->y_max, area->y_max - o.edge_clearance);
        }
        if (target->width() <= 0 || target->height() <= 0) {
            throw std::invalid_argument("--margin: " + std::to_string(o.margin) +
                                        " mm leaves no room in the fit box");
        }
    }
    double scale = o.scale != 0 ? o.scale : 1.0;
    if (target || !o.align.empty()) {
        if (!r.before) throw std::invalid_argument("--fit/--align: the drawing is empty");
        const Box2 turned = m.apply(*r.before);
        if (target) {
            const double w = turned.width(), h = turned.height();
            if (w <= 0 && h <= 0)
                throw std::invalid_argument("--fit: the drawing is a single point");
            scale = std::min(w > 0 ? target->width() / w : INFINITY,
                             h > 0 ? target->height() / h : INFINITY);
        }
        m = m.then({scale, 0, 0, scale, 0, 0});
        const Box2 sized = m.apply(*r.before);
        const auto [fx, fy] = anchor(o.align.empty() ? "center" : o.align, o.origin == "top-left");
        const Box2 goal = target ? *target : Box2{};
        const double dx = goal.x_min + fx * goal.width() - (sized.x_min + fx * sized.width());
        const double dy = goal.y_min + fy * goal.height() - (sized.y_min + fy * sized.height());
        m = m.then({1, 0, 0, 1, dx, dy});
    } else if (scale != 1.0) {
        m = m.then({scale, 0, 0, scale, 0, 0});
    }
    if (o.translate) m = m.then({1, 0, 0, 1, o.translate->first, o.translate->second});

    Path out = path;
    for (Subpath& s : out.subpaths) {
        for (PointMutRef p : s.points) m.apply(p[0], p[1]);
    }
    r.scale = scale;
    r.after = r.before ? std::optional<Box2>(m.apply(*r.before)) : std::nullopt;
    if (report != nullptr) *report = r;
    return out;
}

}  // namespace pathstream::host
