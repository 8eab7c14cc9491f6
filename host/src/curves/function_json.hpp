// The JSON path format's function subpaths ({"basis": "function", "x": "...", "t": [a, b]}):
// read, checked and fitted into a proven Bezier chain.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "pathstream/host/path.hpp"
#include "pathstream/machine/json_document.hpp"

namespace pathstream::host::curves {

/// The function subpath `v` at `pointer` as an open Bezier chain (kBezier) within
/// `tolerance_mm` of the curve, coordinates times `scale` (the file's unit in mm). Sets `axes`
/// (2 or 3: x, y and an optional z) or checks the subpath against it. The fit may evaluate at
/// most `cells_left` interval cells, which it lowers by those it used. Throws InputError at
/// the offending value; an expression's error at its column within the string.
Subpath read_function_subpath(const JsonChecker& c, const nlohmann::json& v,
                              const std::string& pointer, Subpath sp, double scale,
                              double tolerance_mm, std::size_t& axes, std::size_t& cells_left);

}  // namespace pathstream::host::curves
