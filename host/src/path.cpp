#include "pathstream/host/path.hpp"

namespace pathstream::host {

const char* basis_name(PathBasis basis) {
    switch (basis) {
        case PathBasis::kBSpline:
            return "bspline";
        case PathBasis::kCatmullRom:
            return "catmull-rom";
        case PathBasis::kBezier:
            return "bezier";
        case PathBasis::kPolyline:
            return "polyline";
    }
    return "?";
}

Path without_subpaths(const Path& path) {
    Path out;
    out.axes = path.axes;
    out.layers = path.layers;
    out.units = path.units;
    out.mm_per_unit = path.mm_per_unit;
    return out;
}

std::string point_count_problem(const Subpath& sp) {
    const std::size_t n = sp.points.size();
    const std::string kind = sp.closed ? "closed " : "open ";
    if (sp.basis == PathBasis::kBezier) {
        const bool ok = sp.closed ? (n >= 3 && n % 3 == 0) : (n >= 4 && n % 3 == 1);
        if (ok) return {};
        return kind + "bezier needs " + (sp.closed ? "3k" : "3k + 1") + " points (k >= 1), got " +
               std::to_string(n);
    }
    const std::size_t needed = sp.closed ? 3 : 2;
    if (n >= needed) return {};
    return kind + basis_name(sp.basis) + " needs at least " + std::to_string(needed) +
           " points, got " + std::to_string(n);
}

}  // namespace pathstream::host
