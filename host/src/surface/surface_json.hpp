// The JSON path format's "view" and "surfaces" (docs/formats-surfaces.md): read, checked and
// turned into the drawing's subpaths.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pathstream/host/surface.hpp"
#include "pathstream/machine/json_document.hpp"

namespace pathstream::host::surface {

/// The view at `pointer` (an object; see the format), and whether it removes hidden lines.
/// Throws InputError there for unknown keys, wrong types and values out of range.
ViewFrame read_view(const JsonChecker& c, const nlohmann::json& v, const std::string& pointer,
                    bool& hidden_lines);

/// The wireframes of the surfaces in the array at "/surfaces", through `frame`, with the
/// parts any of them hides removed when `hidden_lines`; model coordinates are multiplied by
/// `scale` (the document's units in mm). Throws InputError at the offending value; also past
/// any of `budget`'s limits.
std::vector<Subpath> read_surfaces(const JsonChecker& c, const nlohmann::json& surfaces,
                                   double scale, const ViewFrame& frame, bool hidden_lines,
                                   double tolerance_mm, const SurfaceBudget& budget,
                                   WireframeFigures& figures);

/// `sp` (3 axes, model mm) projected through `frame` onto the drawing: a Bezier subpath of 2
/// axes, exact under an orthographic view, fitted within `tolerance_mm` under perspective.
Subpath project_subpath(const Subpath& sp, const ViewFrame& frame, double tolerance_mm);

}  // namespace pathstream::host::surface
