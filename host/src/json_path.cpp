#include "pathstream/host/json_path.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>

#include "curves/function_json.hpp"
#include "nurbs/nurbs.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/json_document.hpp"
#include "surface/surface_json.hpp"

namespace pathstream::host {

namespace {

using nlohmann::json;

constexpr std::size_t kMaxAxes = 8;
constexpr double kMaxCoordinateMm = 1e6;  // 1 km: beyond any plotter; catches unit mix-ups

class Reader : public JsonChecker {
public:
    Reader(const std::string& text, const std::string& file, double nurbs_tolerance_mm,
           const JsonPathBudget& budget, FlatNumberArrays& flat)
        : JsonChecker(text, file),
          nurbs_tolerance_mm_(nurbs_tolerance_mm),
          budget_(budget),
          function_cells_left_(budget.function_cells),
          flat_(flat) {}

    PathBasis basis(const json& v, const std::string& pointer) const {
        if (!v.is_string()) fail(pointer, "basis must be a string");
        const std::string s = v.get<std::string>();
        if (s == "bspline") return PathBasis::kBSpline;
        if (s == "catmull-rom") return PathBasis::kCatmullRom;
        if (s == "bezier") return PathBasis::kBezier;
        if (s == "polyline") return PathBasis::kPolyline;
        if (s == "nurbs") {
            fail(pointer, "basis nurbs is given per subpath, with its degree and knots");
        }
        if (s == "function") {
            fail(pointer, "basis function is given per subpath, with its x, y (z) and t");
        }
        fail(pointer, "unknown basis \"" + s +
                          "\" (expected bspline, catmull-rom, bezier, polyline, nurbs or "
                          "function)");
    }

    bool boolean(const json& v, const std::string& pointer, const char* what) const {
        if (!v.is_boolean()) fail(pointer, std::string(what) + " must be true or false");
        return v.get<bool>();
    }

    double coordinate(const json& v, const std::string& pointer, double scale) const {
        if (!v.is_number()) fail(pointer, "coordinate must be a number");
        return coordinate_mm(
            v.get<double>(), [&] { return pointer; }, scale);
    }

    /// A number's coordinate in mm; `pointer()` gives its place, only for an error.
    template <class Pointer>
    double coordinate_mm(double x, const Pointer& pointer, double scale) const {
        if (!std::isfinite(x)) fail(pointer(), "coordinate is not finite");
        const double mm = x * scale;
        if (std::fabs(mm) > kMaxCoordinateMm) {
            std::ostringstream m;
            m << "coordinate " << x << " is out of range (|value| <= " << kMaxCoordinateMm
              << " mm)";
            fail(pointer(), m.str());
        }
        return mm;
    }

    Subpath subpath(const json& v, const std::string& pointer, PathBasis default_basis,
                    bool default_closed, double scale, std::size_t& axes) const {
        Subpath sp;
        sp.basis = default_basis;
        sp.closed = default_closed;
        sp.location = locate(pointer);
        if (!v.is_object()) fail(pointer, "subpath must be an object with \"points\"");
        if (v.contains("basis") && v["basis"] == "nurbs")
            return nurbs_subpath(v, pointer, sp, scale, axes);
        if (v.contains("basis") && v["basis"] == "function") {
            return curves::read_function_subpath(*this, v, pointer, sp, scale, nurbs_tolerance_mm_,
                                                 axes, function_cells_left_);
        }
        only_keys(v, pointer, {"basis", "closed", "points"});
        if (v.contains("basis")) sp.basis = basis(v["basis"], pointer + "/basis");
        if (v.contains("closed")) sp.closed = boolean(v["closed"], pointer + "/closed", "closed");
        if (!v.contains("points")) fail(pointer, "subpath has no \"points\"");
        sp.points = points(v["points"], pointer + "/points", scale, axes);
        check_count(sp, pointer + "/points");
        return sp;
    }

    PointList points(const json& v, const std::string& pointer, double scale,
                     std::size_t& axes) const {
        if (!v.is_array()) fail(pointer, "points must be an array of [x, y, ...] arrays");
        if (const auto flat = flat_.found.find(pointer); flat != flat_.found.end()) {
            FlatNumberArrays::Rows rows = std::move(flat->second);
            flat_.found.erase(flat);  // freed once the points are made
            return flat_points(rows, pointer, scale, axes);
        }
        PointList out;
        for (std::size_t i = 0; i < v.size(); ++i) {
            const std::string p = pointer + "/" + std::to_string(i);
            const json& pt = v[i];
            if (!pt.is_array()) fail(p, "point must be an array of coordinates");
            if (axes == 0) {
                if (pt.size() < 1 || pt.size() > kMaxAxes) {
                    fail(p,
                         "point has " + std::to_string(pt.size()) + " coordinates (1 to 8 axes)");
                }
                axes = pt.size();
            } else if (pt.size() != axes) {
                fail(p, "point has " + std::to_string(pt.size()) + " coordinates, expected " +
                            std::to_string(axes));
            }
            PathPoint point;
            for (std::size_t a = 0; a < pt.size(); ++a) {
                point.push_back(coordinate(pt[a], p + "/" + std::to_string(a), scale));
            }
            out.push_back(std::move(point));
        }
        return out;
    }

    /// points() of an array read flat: the same checks in the same order, the same messages.
    PointList flat_points(const FlatNumberArrays::Rows& rows, const std::string& pointer,
                          double scale, std::size_t& axes) const {
        PointList out;
        const double* value = rows.values.data();
        for (std::size_t i = 0; i < rows.widths.size(); ++i) {
            const std::size_t width = rows.widths[i];
            const auto p = [&] { return pointer + "/" + std::to_string(i); };
            if (axes == 0) {
                if (width < 1 || width > kMaxAxes) {
                    fail(p(), "point has " + std::to_string(width) + " coordinates (1 to 8 axes)");
                }
                axes = width;
            } else if (width != axes) {
                fail(p(), "point has " + std::to_string(width) + " coordinates, expected " +
                              std::to_string(axes));
            }
            if (out.empty()) out.reserve(rows.widths.size(), width);
            double point[kMaxAxes];
            for (std::size_t a = 0; a < width; ++a) {
                point[a] = coordinate_mm(
                    *value++, [&] { return p() + "/" + std::to_string(a); }, scale);
            }
            out.push_back(PointRef(point, width));
        }
        return out;
    }

    /// A list of finite numbers ("knots", "weights").
    std::vector<double> numbers(const json& v, const std::string& pointer, const char* what) const {
        if (!v.is_array()) fail(pointer, std::string(what) + " must be an array of numbers");
        std::vector<double> out;
        for (std::size_t i = 0; i < v.size(); ++i) {
            if (!v[i].is_number() || !std::isfinite(v[i].get<double>())) {
                fail(pointer + "/" + std::to_string(i),
                     std::string(what) + " must be finite numbers");
            }
            out.push_back(v[i].get<double>());
        }
        return out;
    }

    // A NURBS subpath becomes an open Bezier chain here, exact or within the tolerance.
    Subpath nurbs_subpath(const json& v, const std::string& pointer, Subpath sp, double scale,
                          std::size_t& axes) const {
        only_keys(v, pointer, {"basis", "closed", "points", "degree", "knots", "weights"});
        if (v.contains("closed") && boolean(v["closed"], pointer + "/closed", "closed")) {
            fail(pointer + "/closed",
                 "a nurbs subpath is open (repeat its first control points to close it)");
        }
        if (!v.contains("points")) fail(pointer, "subpath has no \"points\"");
        nurbs::Nurbs curve;
        if (v.contains("degree")) {
            const json& d = v["degree"];
            if (!d.is_number_integer() || d.get<long>() < 1 || d.get<long>() > nurbs::kMaxDegree) {
                fail(pointer + "/degree", "degree must be a whole number from 1 to 5");
            }
            curve.degree = static_cast<int>(d.get<long>());
        }
        curve.points = points(v["points"], pointer + "/points", scale, axes).vectors();
        if (curve.points.size() < static_cast<std::size_t>(curve.degree) + 1) {
            fail(pointer + "/points", "degree " + std::to_string(curve.degree) +
                                          " needs at least " + std::to_string(curve.degree + 1) +
                                          " control points, got " +
                                          std::to_string(curve.points.size()));
        }
        curve.knots = v.contains("knots")
                          ? numbers(v["knots"], pointer + "/knots", "knots")
                          : nurbs::clamped_uniform_knots(curve.points.size(), curve.degree);
        if (v.contains("weights"))
            curve.weights = numbers(v["weights"], pointer + "/weights", "weights");
        if (const std::string problem = nurbs::nurbs_problem(curve); !problem.empty()) {
            fail(pointer, "nurbs: " + problem);
        }
        try {
            sp.points = nurbs::nurbs_to_bezier(curve, nurbs_tolerance_mm_);
        } catch (const std::length_error& e) {
            fail(pointer, e.what());
        }
        if (sp.points.empty()) fail(pointer, "nurbs: the curve is a single point");
        sp.basis = PathBasis::kBezier;
        sp.closed = false;
        return sp;
    }

    void check_count(const Subpath& sp, const std::string& pointer) const {
        if (const std::string problem = point_count_problem(sp); !problem.empty())
            fail(pointer, problem);
    }

    Path path(const json& root) const {
        if (!root.is_object()) fail("", "a path file must be a JSON object");
        only_keys(root, "", {"units", "basis", "closed", "subpaths", "points", "view", "surfaces"});
        double scale = 1.0;
        if (root.contains("units")) {
            const json& u = root["units"];
            if (!u.is_string()) fail("/units", "units must be \"mm\" or \"in\"");
            const std::string s = u.get<std::string>();
            if (s == "in")
                scale = 25.4;
            else if (s != "mm")
                fail("/units", "unknown units \"" + s + "\" (expected mm or in)");
        }
        const PathBasis default_basis =
            root.contains("basis") ? basis(root["basis"], "/basis") : PathBasis::kBSpline;
        const bool default_closed =
            root.contains("closed") ? boolean(root["closed"], "/closed", "closed") : false;

        Path path;
        std::size_t axes = 0;
        const bool has_points = root.contains("points"), has_subpaths = root.contains("subpaths");
        const bool has_surfaces = root.contains("surfaces");
        if (has_points == has_subpaths && !(has_surfaces && !has_points)) {
            fail("", "give either \"points\" (one subpath) or \"subpaths\", not both or neither");
        }
        // Located from here on without an error: "/points" or "/subpaths/N", not the points.
        locate_shallow(has_points ? 1 : 2);
        if (has_points) {
            Subpath sp;
            sp.basis = default_basis;
            sp.closed = default_closed;
            sp.location = locate("/points");
            sp.points = points(root["points"], "/points", scale, axes);
            check_count(sp, "/points");
            path.subpaths.push_back(std::move(sp));
        } else if (has_subpaths) {
            const json& list = root["subpaths"];
            if (!list.is_array() || list.empty())
                fail("/subpaths", "subpaths must be a non-empty array");
            for (std::size_t i = 0; i < list.size(); ++i) {
                path.subpaths.push_back(subpath(list[i], "/subpaths/" + std::to_string(i),
                                                default_basis, default_closed, scale, axes));
            }
        }
        path.axes = axes;
        if (root.contains("view") || has_surfaces) project(root, scale, path);
        if (scale != 1.0) {
            path.units = "in";
            path.mm_per_unit = scale;
        }
        return path;
    }

private:
    // Under a view the drawing is the page: 3-D subpaths are projected onto it, 2-D ones (a
    // frame, a title) drawn as they are, and the surfaces' wireframes added after them.
    void project(const json& root, double scale, Path& path) const {
        bool hidden_lines = false;
        const ViewFrame frame = root.contains("view")
                                    ? surface::read_view(*this, root["view"], "/view", hidden_lines)
                                    : view_frame(SurfaceView{});
        if (path.axes == 3) {
            for (Subpath& sp : path.subpaths) {
                try {
                    sp = surface::project_subpath(sp, frame, nurbs_tolerance_mm_);
                } catch (const std::domain_error& e) {
                    fail("/view", e.what());
                }
            }
        } else if (path.axes != 2 && !path.subpaths.empty()) {
            fail("/subpaths",
                 "under a view, points have 3 coordinates (projected) or 2 (drawn "
                 "on the page as they are)");
        }
        if (root.contains("surfaces")) {
            WireframeFigures figures;
            for (Subpath& sp :
                 surface::read_surfaces(*this, root["surfaces"], scale, frame, hidden_lines,
                                        nurbs_tolerance_mm_, budget_.surfaces, figures)) {
                path.subpaths.push_back(std::move(sp));
            }
            if (path.subpaths.empty()) fail("/surfaces", "the surfaces draw no curve");
        }
        path.axes = 2;
    }

    double nurbs_tolerance_mm_;
    JsonPathBudget budget_;
    mutable std::size_t function_cells_left_;  // over every function subpath of the file
    FlatNumberArrays& flat_;
};

}  // namespace

Path parse_json_path(const std::string& text, const std::string& file, double nurbs_tolerance_mm,
                     const JsonPathBudget& budget) {
    if (!(nurbs_tolerance_mm > 0) || !std::isfinite(nurbs_tolerance_mm)) {
        throw std::invalid_argument(
            "parse_json_path: the NURBS tolerance must be positive and finite");
    }
    // The points arrays are read flat: a document tree of 10^6 points is ~100 MB.
    FlatNumberArrays flat;
    flat.where = {"/points", "/subpaths/*/points"};
    const nlohmann::json document = parse_json_document(text, file, &flat);
    return Reader(text, file, nurbs_tolerance_mm, budget, flat).path(document);
}

Path load_json_path(const std::string& file, double nurbs_tolerance_mm) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return parse_json_path(buffer.str(), file, nurbs_tolerance_mm);
}

}  // namespace pathstream::host
