// Surfaces in a JSON path file: Bezier patches (inline, or as vertices and index lists as the
// Newell teapot is distributed) and surfaces of revolution of a profile subpath.
#include "surface_json.hpp"

#include <cmath>

#include "pathstream/machine/input_error.hpp"
#include "project_curve.hpp"

namespace pathstream::host::surface {
namespace {

using nlohmann::json;

constexpr double kMaxCoordinateMm = 1e6;
constexpr std::size_t kMaxIso = 1000;

double number(const JsonChecker& c, const json& v, const std::string& pointer, const char* what) {
    if (!v.is_number() || !std::isfinite(v.get<double>())) {
        c.fail(pointer, std::string(what) + " must be a finite number");
    }
    return v.get<double>();
}

Point3 point3(const JsonChecker& c, const json& v, const std::string& pointer, double scale) {
    if (!v.is_array() || v.size() != 3) c.fail(pointer, "a surface point is [x, y, z]");
    Point3 p;
    for (std::size_t k = 0; k < 3; ++k) {
        p[k] = number(c, v[k], pointer + "/" + std::to_string(k), "coordinate") * scale;
        if (std::abs(p[k]) > kMaxCoordinateMm) {
            c.fail(pointer + "/" + std::to_string(k),
                   "coordinate is out of range (|value| <= " + std::to_string(kMaxCoordinateMm) +
                       " mm)");
        }
    }
    return p;
}

std::size_t whole(const JsonChecker& c, const json& v, const std::string& pointer, long lo, long hi,
                  const char* what) {
    if (!v.is_number_integer() || v.get<long>() < lo || v.get<long>() > hi) {
        c.fail(pointer, std::string(what) + " must be a whole number from " + std::to_string(lo) +
                            " to " + std::to_string(hi));
    }
    return static_cast<std::size_t>(v.get<long>());
}

IsoCounts iso(const JsonChecker& c, const json& s, const std::string& pointer) {
    IsoCounts n;
    if (!s.contains("iso")) return n;
    const json& v = s["iso"];
    if (!v.is_object()) c.fail(pointer + "/iso", "iso must be an object {\"u\": N, \"v\": N}");
    c.only_keys(v, pointer + "/iso", {"u", "v"});
    if (v.contains("u")) n.u = whole(c, v["u"], pointer + "/iso/u", 0, kMaxIso, "iso u");
    if (v.contains("v")) n.v = whole(c, v["v"], pointer + "/iso/v", 0, kMaxIso, "iso v");
    return n;
}

std::vector<BezierPatch> patches(const JsonChecker& c, const json& s, const std::string& pointer,
                                 double scale) {
    int du = 3, dv = 3;
    if (s.contains("degree")) {
        const json& d = s["degree"];
        if (d.is_array() && d.size() == 2) {
            du = static_cast<int>(whole(c, d[0], pointer + "/degree/0", 1, 3, "degree"));
            dv = static_cast<int>(whole(c, d[1], pointer + "/degree/1", 1, 3, "degree"));
        } else {
            du = dv = static_cast<int>(whole(c, d, pointer + "/degree", 1, 3, "degree"));
        }
    }
    std::vector<Point3> vertices;
    const bool indexed = s.contains("vertices");
    if (indexed) {
        const json& v = s["vertices"];
        if (!v.is_array()) c.fail(pointer + "/vertices", "vertices must be an array of [x, y, z]");
        for (std::size_t i = 0; i < v.size(); ++i) {
            vertices.push_back(point3(c, v[i], pointer + "/vertices/" + std::to_string(i), scale));
        }
    }
    if (!s.contains("patches")) c.fail(pointer, "a bezier surface needs \"patches\"");
    const json& list = s["patches"];
    if (!list.is_array() || list.empty()) {
        c.fail(pointer + "/patches", "patches must be a non-empty array");
    }
    const std::size_t count = static_cast<std::size_t>((du + 1) * (dv + 1));
    std::vector<BezierPatch> out;
    for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string at = pointer + "/patches/" + std::to_string(i);
        const json& p = list[i];
        if (!p.is_array() || p.size() != count) {
            c.fail(at, "a patch of degree " + std::to_string(du) + " x " + std::to_string(dv) +
                           " has " + std::to_string(count) +
                           (indexed ? " vertex indices" : " control points"));
        }
        BezierPatch patch;
        patch.degree_u = du;
        patch.degree_v = dv;
        patch.location = c.locate(pointer);
        for (std::size_t k = 0; k < count; ++k) {
            const std::string ak = at + "/" + std::to_string(k);
            if (indexed) {
                const long last = static_cast<long>(vertices.size()) - 1;
                if (last < 0) c.fail(pointer + "/vertices", "vertices is empty");
                patch.points.push_back(vertices[whole(c, p[k], ak, 0, last, "a vertex index")]);
            } else {
                patch.points.push_back(point3(c, p[k], ak, scale));
            }
        }
        out.push_back(std::move(patch));
    }
    return out;
}

// The profile of a surface of revolution: a subpath of [radius, height] points.
std::vector<BezierSegment> read_profile(const JsonChecker& c, const json& s,
                                        const std::string& pointer, double scale) {
    const std::string at = pointer + "/profile";
    if (!s.contains("profile")) c.fail(pointer, "a revolution surface needs \"profile\"");
    const json& v = s["profile"];
    if (!v.is_object())
        c.fail(at, "profile is a subpath: {\"basis\": ..., \"points\": [[r, h], ...]}");
    c.only_keys(v, at, {"basis", "closed", "points"});
    Subpath sp;
    sp.basis = PathBasis::kBSpline;
    if (v.contains("basis")) {
        const json& b = v["basis"];
        if (b == "bspline") {
            sp.basis = PathBasis::kBSpline;
        } else if (b == "catmull-rom") {
            sp.basis = PathBasis::kCatmullRom;
        } else if (b == "bezier") {
            sp.basis = PathBasis::kBezier;
        } else if (b == "polyline") {
            sp.basis = PathBasis::kPolyline;
        } else {
            c.fail(at + "/basis", "a profile's basis is bspline, catmull-rom, bezier or polyline");
        }
    }
    if (v.contains("closed")) {
        if (!v["closed"].is_boolean()) c.fail(at + "/closed", "closed must be true or false");
        sp.closed = v["closed"].get<bool>();
    }
    if (!v.contains("points") || !v["points"].is_array()) {
        c.fail(at, "profile needs \"points\": [[radius, height], ...]");
    }
    const json& pts = v["points"];
    for (std::size_t i = 0; i < pts.size(); ++i) {
        const std::string ai = at + "/points/" + std::to_string(i);
        if (!pts[i].is_array() || pts[i].size() != 2)
            c.fail(ai, "a profile point is [radius, height]");
        const double r = number(c, pts[i][0], ai + "/0", "radius") * scale;
        const double h = number(c, pts[i][1], ai + "/1", "height") * scale;
        if (std::abs(r) > kMaxCoordinateMm || std::abs(h) > kMaxCoordinateMm) {
            c.fail(ai, "coordinate is out of range (|value| <= 1e6 mm)");
        }
        sp.points.push_back({r, h});
    }
    if (const std::string problem = point_count_problem(sp); !problem.empty()) {
        c.fail(at + "/points", problem);
    }
    Path one;
    one.axes = 2;
    one.subpaths.push_back(std::move(sp));
    return to_bezier_segments(one);
}

}  // namespace

ViewFrame read_view(const JsonChecker& c, const json& v, const std::string& pointer,
                    bool& hidden_lines) {
    if (!v.is_object()) c.fail(pointer, "view must be an object");
    c.only_keys(
        v, pointer,
        {"projection", "azimuth", "elevation", "roll", "scale", "eye_distance", "hidden_lines"});
    hidden_lines = false;
    if (v.contains("hidden_lines")) {
        const json& h = v["hidden_lines"];
        if (h == "remove") {
            hidden_lines = true;
        } else if (h != "draw") {
            c.fail(pointer + "/hidden_lines", "hidden_lines must be \"draw\" or \"remove\"");
        }
    }
    SurfaceView view;
    if (v.contains("projection")) {
        const json& p = v["projection"];
        if (p == "orthographic") {
            view.projection = SurfaceView::Projection::kOrthographic;
        } else if (p == "perspective") {
            view.projection = SurfaceView::Projection::kPerspective;
        } else {
            c.fail(pointer + "/projection",
                   "projection must be \"orthographic\" or \"perspective\"");
        }
    }
    auto angle = [&](const char* key, double& out) {
        if (!v.contains(key)) return;
        out = number(c, v[key], pointer + "/" + key, key);
        if (std::abs(out) > 360)
            c.fail(pointer + "/" + key, std::string(key) + " is in degrees, -360 to 360");
    };
    angle("azimuth", view.azimuth_deg);
    angle("elevation", view.elevation_deg);
    angle("roll", view.roll_deg);
    if (v.contains("scale")) {
        view.scale = number(c, v["scale"], pointer + "/scale", "scale");
        if (!(view.scale > 0) || view.scale > 1e6)
            c.fail(pointer + "/scale", "scale must be in (0, 1e6]");
    }
    if (v.contains("eye_distance")) {
        view.eye_distance = number(c, v["eye_distance"], pointer + "/eye_distance", "eye_distance");
        if (!(view.eye_distance > 0))
            c.fail(pointer + "/eye_distance", "eye_distance must be positive");
    }
    if (view.projection == SurfaceView::Projection::kPerspective && !v.contains("eye_distance")) {
        c.fail(pointer, "a perspective view needs \"eye_distance\" (model units from the origin)");
    }
    return view_frame(view);
}

std::vector<Subpath> read_surfaces(const JsonChecker& c, const json& surfaces, double scale,
                                   const ViewFrame& frame, bool hidden_lines, double tolerance_mm,
                                   const SurfaceBudget& budget, WireframeFigures& figures) {
    if (!surfaces.is_array() || surfaces.empty()) {
        c.fail("/surfaces", "surfaces must be a non-empty array");
    }
    std::vector<SurfaceInput> parsed;
    double estimate = 0;
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        SurfaceInput item;
        const std::string at = "/surfaces/" + std::to_string(i);
        const json& s = surfaces[i];
        if (!s.is_object() || !s.contains("type")) {
            c.fail(at, "a surface is an object with \"type\": \"bezier\" or \"revolution\"");
        }
        item.counts = iso(c, s, at);
        if (s["type"] == "bezier") {
            c.only_keys(s, at, {"type", "degree", "patches", "vertices", "iso"});
            item.patches = patches(c, s, at, scale);
        } else if (s["type"] == "revolution") {
            c.only_keys(s, at, {"type", "profile", "axis", "angle", "iso"});
            RevolutionSurface r;
            r.location = c.locate(at);
            r.profile = read_profile(c, s, at, scale);
            if (s.contains("axis")) {
                const json& a = s["axis"];
                if (!a.is_array() || a.size() != 2) {
                    c.fail(at + "/axis",
                           "axis is [[x, y, z] of a point, [x, y, z] of its direction]");
                }
                r.axis_point = point3(c, a[0], at + "/axis/0", scale);
                r.axis_direction = point3(c, a[1], at + "/axis/1", 1.0);
            }
            if (s.contains("angle")) {
                r.angle_deg = number(c, s["angle"], at + "/angle", "angle");
                if (!(r.angle_deg > 0 && r.angle_deg <= 360)) {
                    c.fail(at + "/angle", "angle must be in (0, 360] degrees");
                }
            }
            item.revolution = std::move(r);
        } else {
            c.fail(at + "/type", "type must be \"bezier\" or \"revolution\"");
        }
        // Checked while reading, so that a huge file stops at the surface that spends it.
        estimate += estimated_curves(item);
        if (estimate > static_cast<double>(budget.curves)) {
            c.fail(at, "more than " + std::to_string(budget.curves) +
                           " iso-curves (the reader's limit): fewer surfaces or iso lines");
        }
        parsed.push_back(std::move(item));
    }
    try {
        return draw_surfaces(parsed, frame, hidden_lines, tolerance_mm, budget, figures);
    } catch (const SurfaceError& e) {
        c.fail("/surfaces/" + std::to_string(e.surface), e.what());
    }
}

Subpath project_subpath(const Subpath& sp, const ViewFrame& frame, double tolerance_mm) {
    Path one;
    one.axes = 3;
    one.subpaths.push_back(sp);
    one.subpaths.back().location = {};
    Subpath out = sp;
    out.basis = PathBasis::kBezier;
    out.closed = false;
    out.points = PointList();
    out.stops.clear();
    out.segment_lines.clear();
    for (const BezierSegment& s : to_bezier_segments(one)) {
        std::vector<Point3> q;
        for (const PathPoint& p : s.p) q.push_back({p[0], p[1], p[2]});
        bool exact = false;
        const std::vector<PathPoint> chain = project_curve(q, {}, frame, tolerance_mm, exact);
        for (std::size_t i = out.points.size() == 0 ? 0 : 1; i < chain.size(); ++i) {
            out.points.push_back(chain[i]);
        }
    }
    return out;
}

}  // namespace pathstream::host::surface
