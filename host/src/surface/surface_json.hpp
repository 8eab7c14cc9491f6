// The JSON path format's "view" and "surfaces" (docs/formats-surfaces.md): read, checked and
// turned into the drawing's subpaths.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "pathstream/host/surface.hpp"
#include "pathstream/machine/json_document.hpp"

namespace pathstream::host::surface {

/// The view at `pointer` (an object; see the format). Throws InputError there for unknown
/// keys, wrong types and values out of range.
ViewFrame read_view(const JsonChecker& c, const nlohmann::json& v, const std::string& pointer);

/// The wireframes of the surfaces in the array at "/surfaces", through `frame`; model
/// coordinates are multiplied by `scale` (the document's units in mm). Adds to `figures`.
/// Throws InputError at the offending value; also when a surface's wireframe would exceed
/// `max_curves` curves in all.
std::vector<Subpath> read_surfaces(const JsonChecker& c, const nlohmann::json& surfaces,
                                   double scale, const ViewFrame& frame, double tolerance_mm,
                                   WireframeFigures& figures, std::size_t max_curves = 200'000);

/// `sp` (3 axes, model mm) projected through `frame` onto the drawing: a Bezier subpath of 2
/// axes, exact under an orthographic view, fitted within `tolerance_mm` under perspective.
Subpath project_subpath(const Subpath& sp, const ViewFrame& frame, double tolerance_mm);

}  // namespace pathstream::host::surface
