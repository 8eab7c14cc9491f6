// The 3-D view of a 3-axis machine (a CNC router: axes x, y, z by name): which axes it shows and
// how a point of them lands on the page. path.svg of `sim --plot` draws it, and the page of
// `pathstream serve` draws the same projection from the preview's x, y, z (web/preview.js).
#pragma once

#include <cstddef>
#include <optional>

#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// The indexes, in the profile's axes, of the axes named "x", "y" and "z".
struct XyzAxes {
    std::size_t x = 0;
    std::size_t y = 1;
    std::size_t z = 2;
};

/// The machine's x, y and z axes when it has 3 or more axes and one named exactly "x", one "y"
/// and one "z" (lower case, as profiles name them), in any order; otherwise none (a pen
/// plotter's x, y: the plots and the page keep their 2-D views). O(axes).
std::optional<XyzAxes> xyz_axes(const MachineProfile& profile);

/// A point of the isometric view: `right` and `up` on the page, mm.
struct IsometricPoint {
    double right = 0;
    double up = 0;
};

/// The standard isometric view, seen from (+x, -y, +z) towards the origin: +x points to the
/// lower right and +y to the upper right, both 30 degrees off the horizontal, +z straight up:
///   right = (x + y) cos 30 deg = (x + y) sqrt(3) / 2,   up = z + (y - x) / 2.
/// It is the orthographic projection along (1, -1, 1) scaled by sqrt(3/2), so that a length
/// along x, y or z keeps its length on the page (an isometric drawing; the true isometric
/// projection is this times sqrt(2/3) = 0.8165). Parallel lines stay parallel.
IsometricPoint isometric(double x, double y, double z);

}  // namespace pathstream::host
