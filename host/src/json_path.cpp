#include "pathstream/host/json_path.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "pathstream/host/input_error.hpp"
#include "pathstream/host/json_document.hpp"

namespace pathstream::host {

namespace {

using nlohmann::json;

constexpr std::size_t kMaxAxes = 8;
constexpr double kMaxCoordinateMm = 1e6;  // 1 km: beyond any plotter; catches unit mix-ups

class Reader : public JsonChecker {
public:
    using JsonChecker::JsonChecker;

    PathBasis basis(const json& v, const std::string& pointer) const {
        if (!v.is_string()) fail(pointer, "basis must be a string");
        const std::string s = v.get<std::string>();
        if (s == "bspline") return PathBasis::kBSpline;
        if (s == "catmull-rom") return PathBasis::kCatmullRom;
        if (s == "bezier") return PathBasis::kBezier;
        if (s == "polyline") return PathBasis::kPolyline;
        fail(pointer, "unknown basis \"" + s + "\" (expected bspline, catmull-rom, bezier or polyline)");
    }

    bool boolean(const json& v, const std::string& pointer, const char* what) const {
        if (!v.is_boolean()) fail(pointer, std::string(what) + " must be true or false");
        return v.get<bool>();
    }

    double coordinate(const json& v, const std::string& pointer, double scale) const {
        if (!v.is_number()) fail(pointer, "coordinate must be a number");
        const double x = v.get<double>();
        if (!std::isfinite(x)) fail(pointer, "coordinate is not finite");
        const double mm = x * scale;
        if (std::fabs(mm) > kMaxCoordinateMm) {
            std::ostringstream m;
            m << "coordinate " << x << " is out of range (|value| <= " << kMaxCoordinateMm
              << " mm)";
            fail(pointer, m.str());
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
        only_keys(v, pointer, {"basis", "closed", "points"});
        if (v.contains("basis")) sp.basis = basis(v["basis"], pointer + "/basis");
        if (v.contains("closed")) sp.closed = boolean(v["closed"], pointer + "/closed", "closed");
        if (!v.contains("points")) fail(pointer, "subpath has no \"points\"");
        sp.points = points(v["points"], pointer + "/points", scale, axes);
        check_count(sp, pointer + "/points");
        return sp;
    }

    std::vector<PathPoint> points(const json& v, const std::string& pointer, double scale,
                                  std::size_t& axes) const {
        if (!v.is_array()) fail(pointer, "points must be an array of [x, y, ...] arrays");
        std::vector<PathPoint> out;
        for (std::size_t i = 0; i < v.size(); ++i) {
            const std::string p = pointer + "/" + std::to_string(i);
            const json& pt = v[i];
            if (!pt.is_array()) fail(p, "point must be an array of coordinates");
            if (axes == 0) {
                if (pt.size() < 1 || pt.size() > kMaxAxes) {
                    fail(p, "point has " + std::to_string(pt.size()) + " coordinates (1 to 8 axes)");
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

    void check_count(const Subpath& sp, const std::string& pointer) const {
        if (const std::string problem = point_count_problem(sp); !problem.empty()) fail(pointer, problem);
    }

    Path path(const json& root) const {
        if (!root.is_object()) fail("", "a path file must be a JSON object");
        only_keys(root, "", {"units", "basis", "closed", "subpaths", "points"});
        double scale = 1.0;
        if (root.contains("units")) {
            const json& u = root["units"];
            if (!u.is_string()) fail("/units", "units must be \"mm\" or \"in\"");
            const std::string s = u.get<std::string>();
            if (s == "in") scale = 25.4;
            else if (s != "mm") fail("/units", "unknown units \"" + s + "\" (expected mm or in)");
        }
        const PathBasis default_basis =
            root.contains("basis") ? basis(root["basis"], "/basis") : PathBasis::kBSpline;
        const bool default_closed =
            root.contains("closed") ? boolean(root["closed"], "/closed", "closed") : false;

        Path path;
        std::size_t axes = 0;
        const bool has_points = root.contains("points"), has_subpaths = root.contains("subpaths");
        if (has_points == has_subpaths) {
            fail("", "give either \"points\" (one subpath) or \"subpaths\", not both or neither");
        }
        if (has_points) {
            Subpath sp;
            sp.basis = default_basis;
            sp.closed = default_closed;
            sp.location = locate("/points");
            sp.points = points(root["points"], "/points", scale, axes);
            check_count(sp, "/points");
            path.subpaths.push_back(std::move(sp));
        } else {
            const json& list = root["subpaths"];
            if (!list.is_array() || list.empty()) fail("/subpaths", "subpaths must be a non-empty array");
            for (std::size_t i = 0; i < list.size(); ++i) {
                path.subpaths.push_back(subpath(list[i], "/subpaths/" + std::to_string(i),
                                                default_basis, default_closed, scale, axes));
            }
        }
        path.axes = axes;
        if (scale != 1.0) {
            path.units = "in";
            path.mm_per_unit = scale;
        }
        return path;
    }
};

}  // namespace

Path parse_json_path(const std::string& text, const std::string& file) {
    return Reader(text, file).path(parse_json_document(text, file));
}

Path load_json_path(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return parse_json_path(buffer.str(), file);
}

}  // namespace pathstream::host
