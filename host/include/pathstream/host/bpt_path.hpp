// Reader of the Bezier patch text form the Newell teapot is distributed in: the patch count,
// then per patch its degrees and control points (docs/formats-surfaces.md).
#pragma once

#include <string>

#include "pathstream/host/path.hpp"
#include "pathstream/host/surface.hpp"

namespace pathstream::host {

/// How a .bpt file is drawn: it holds no view, so the reader's.
struct BptOptions {
    SurfaceView view;            ///< default: orthographic, azimuth -30, elevation 25, scale 1
    IsoCounts counts{4, 4};      ///< iso lines per patch
    bool hidden_lines = true;    ///< remove what the patches hide
    double tolerance_mm = 0.01;  ///< for fitted (perspective) curves; > 0
    SurfaceBudget budget;
};

/// The wireframe of the patches in `text` (named `file` in messages) as a 2-D path. Throws
/// InputError ("file:line:col: what is wrong") for a missing or malformed count, degrees
/// outside 1 to 3, a point without three finite numbers within 1e6, missing or extra data,
/// more than 100,000 patches, and past the budget ("file: ..."). Cost: linear in the text,
/// then as draw_surfaces.
Path parse_bpt_path(const std::string& text, const std::string& file,
                    const BptOptions& options = {});

}  // namespace pathstream::host
