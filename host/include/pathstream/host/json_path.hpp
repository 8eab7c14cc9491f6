// Reader of the JSON path format (docs/formats.md).
#pragma once

#include <string>

#include "pathstream/host/path.hpp"
#include "pathstream/host/surface.hpp"

namespace pathstream::host {

/// What a JSON path may cost before the read fails (the reader's limits).
struct JsonPathBudget {
    SurfaceBudget surfaces;  ///< its "surfaces"
    /// Interval cells the proofs of all its function subpaths may evaluate (about 10 us each).
    std::size_t function_cells = 50'000'000;
};

/// Parses a JSON path document. `file` names the source in error messages. Subpaths with
/// basis "nurbs" become open Bezier chains (kBezier): exact for non-rational curves of degree
/// 1 to 3, else within `nurbs_tolerance_mm` (> 0).
/// Throws InputError ("file:line:col: what is wrong") on malformed JSON, unknown keys,
/// wrong types, non-finite or out-of-range numbers, too few points, unknown bases and
/// unusable NURBS (degree, knots, weights), and surfaces past `budget`. "surfaces" and "view"
/// draw wireframes of surfaces (docs/formats-surfaces.md), fitted where they must be within
/// `nurbs_tolerance_mm` too. Throws std::invalid_argument for a bad tolerance.
Path parse_json_path(const std::string& text, const std::string& file,
                     double nurbs_tolerance_mm = 0.01, const JsonPathBudget& budget = {});

/// Reads and parses a JSON path file. Throws InputError, also when it cannot be read.
Path load_json_path(const std::string& file, double nurbs_tolerance_mm = 0.01);

}  // namespace pathstream::host
