// A function subpath read from JSON: its expressions parsed (errors at their column), its t
// range checked, and the fit's proven chain scaled to millimetres.
#include "function_json.hpp"

#include <cmath>

#include "fit_function.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host::curves {

Subpath read_function_subpath(const JsonChecker& c, const nlohmann::json& v,
                              const std::string& pointer, Subpath sp, double scale,
                              double tolerance_mm, std::size_t& axes, std::size_t& cells_left) {
    c.only_keys(v, pointer, {"basis", "x", "y", "z", "t"});
    FunctionCurve curve;
    for (const char* key : {"x", "y", "z"}) {
        const std::string at = pointer + "/" + key;
        if (!v.contains(key)) {
            if (key[0] == 'z') break;
            c.fail(pointer, std::string("a function subpath needs \"") + key + "\"");
        }
        if (!v[key].is_string()) c.fail(at, std::string(key) + " must be an expression in t");
        try {
            curve.coordinates.push_back(parse_expression(v[key].get<std::string>()));
        } catch (const ExpressionError& e) {
            // The string's first character is one past its opening quote (escapes shift it).
            SourceLocation where = c.locate(at);
            if (where.line != 0) where.column += e.column();
            throw InputError(c.file(), where, std::string(key) + ": " + e.message());
        }
    }
    if (!v.contains("t") || !v["t"].is_array() || v["t"].size() != 2 || !v["t"][0].is_number() ||
        !v["t"][1].is_number()) {
        c.fail(v.contains("t") ? pointer + "/t" : pointer,
               "a function subpath needs \"t\": [t0, t1], two numbers");
    }
    curve.t0 = v["t"][0].get<double>();
    curve.t1 = v["t"][1].get<double>();
    if (!std::isfinite(curve.t0) || !std::isfinite(curve.t1) || !(curve.t1 > curve.t0)) {
        c.fail(pointer + "/t", "t must be two finite numbers, the second larger");
    }
    const std::size_t n = curve.coordinates.size();
    if (axes == 0) {
        axes = n;
    } else if (axes != n) {
        c.fail(pointer, "the function has " + std::to_string(n) + " coordinates, expected " +
                            std::to_string(axes));
    }
    FitLimits limits;
    limits.max_cells = cells_left;
    FitFigures figures;
    std::vector<PathPoint> chain;
    try {
        // The fit works in the file's unit: its tolerance is the same distance in mm.
        chain = fit_function_curve(curve, tolerance_mm / scale, &figures, limits);
    } catch (const FitError& e) {
        c.fail(pointer, std::string("function: ") + e.what());
    }
    cells_left -= std::min(cells_left, figures.cells);
    for (PathPoint& p : chain) {
        for (double& x : p) {
            x *= scale;
            if (!(std::abs(x) <= 1e6)) {
                c.fail(pointer,
                       "function: the curve leaves the coordinate range (|value| <= "
                       "1e6 mm)");
            }
        }
        sp.points.push_back(p);
    }
    sp.basis = PathBasis::kBezier;
    sp.closed = false;
    return sp;
}

}  // namespace pathstream::host::curves
