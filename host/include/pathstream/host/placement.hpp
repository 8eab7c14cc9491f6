// Placement of a path on the machine after reading: rotate, flip, scale or fit, align,
// translate (docs/cli.md, "Path file options").
#pragma once

#include <optional>
#include <string>

#include "pathstream/host/path.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// An axis-aligned rectangle in the x-y plane, mm (min <= max).
struct Box2 {
    double x_min = 0, y_min = 0, x_max = 0, y_max = 0;
    double width() const { return x_max - x_min; }
    double height() const { return y_max - y_min; }
};

/// What to do to a path's x and y (other axes are never changed). Applied in this order:
/// rotate, flip-y, scale or fit, align, translate. Every step is an affine map of the control
/// points, which is exact for every basis (each curve point is an affine combination of them).
struct PlacementOptions {
    int rotate = 0;       ///< 0, 90, 180 or 270 degrees about the origin, x towards y
    bool flip_y = false;  ///< y -> -y
    double scale = 0;     ///< > 0: scale x and y about the origin; 0: none
    /// "": no fit; "area": the machine's work area; a paper a0..a6, letter, legal, tabloid
    /// (portrait, [0, W] x [0, H]; append "-landscape" for W > H). Keeps the aspect ratio.
    std::string fit;
    double margin = 0;  ///< mm kept free on every side of the fit box
    /// Where the drawing goes in the fit box: center, top-left, top, top-right, left, right,
    /// bottom-left, bottom, bottom-right (default center). Without --fit, the named point of
    /// the drawing's box is moved to (0, 0).
    std::string align;
    /// Which corner of the paper the machine's origin is: "top-left" (y grows downward, as in
    /// SVG) or "bottom-left" (y grows upward). Decides which edge "top" in `align` means.
    std::string origin = "top-left";
    std::optional<std::pair<double, double>> translate;  ///< mm added last
    /// mm a fit keeps from the machine's travel edges (not an option: the caller sets the
    /// planner's chord tolerance plus one LSB, so that no planned tick of a drawing fitted to
    /// the whole work area leaves it). Used only with a work area.
    double edge_clearance = 0;

    /// Whether any option asks for a change.
    bool active() const {
        return rotate != 0 || flip_y || scale != 0 || !fit.empty() || !align.empty() ||
               translate.has_value();
    }
};

/// Figures of one placement, for check.
struct PlacementReport {
    std::optional<Box2> before, after;  ///< exact box of the drawn curves; none when empty
    double scale = 1;                   ///< the scale applied (from --scale or the fit)
};

/// Exact x-y bounding box of the drawn curves (not the control points); none without any.
std::optional<Box2> drawing_box(const Path& path);

/// The machine's work area in x and y (the first two axes' travel), when it has both.
std::optional<Box2> work_area(const MachineProfile& profile);

/// A named paper's box: "a0".."a6", "letter", "legal", "tabloid", optionally "-landscape".
/// Throws std::invalid_argument for an unknown name (the message lists the names).
Box2 paper_box(const std::string& name);

/// The placed path. `area`: the machine's work area, needed by fit "area". Throws
/// std::invalid_argument with a message naming the option for bad values, a fit without a
/// box, a fit or align of an empty drawing, a margin leaving no room, or a path with fewer
/// than 2 axes.
Path place_path(const Path& path, const PlacementOptions& options, const std::optional<Box2>& area,
                PlacementReport* report = nullptr);

}  // namespace pathstream::host
