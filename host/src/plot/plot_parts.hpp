// Private pieces the plot writers share: margins and dashes, axis names, pen-up shading,
// decimation, sizes, layer colours. Not part of the host library's interface.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "pathstream/host/plot.hpp"
#include "svg_canvas.hpp"

namespace pathstream::host::plot::detail {

inline constexpr double kMarginLeft = 74, kMarginRight = 22, kMarginTop = 56, kMarginBottom = 66;
inline constexpr const char* kPenUpDash = "6 4";    ///< executed pen-up moves
inline constexpr const char* kTravelDash = "10 6";  ///< the ideal path's pen-up travel
inline constexpr const char* kPenUpShade = "#eceef0";

/// The profile's name of `axis`, else x, y, z, a, b, c, u, v by index.
std::string axis_name(const MachineProfile& profile, std::size_t axis);

/// Appends a pixel point unless it is within `min_px` of the last one kept.
void add_px(std::vector<Point>& run, Point p, double min_px = 0.4);

/// Draws an executed trace as pen-down (solid) and pen-up (dashed) runs, each point through
/// `to_px` (the 2-D view or the isometric one), thinned to points at least 0.75 px apart, the
/// boundary point shared with the next run.
void draw_executed(Canvas& c, const std::vector<TracePoint>& s, const std::string& colour,
                   double width, const std::function<Point(const TracePoint&)>& to_px);

/// The legend's swatch of the pen-up shading.
LegendEntry pen_up_legend();
/// Shades the pen-up intervals of a run (merging ones closer than a pixel).
void shade_pen_up(Canvas& c, const RunRecord& r);

/// decimate_min_max of a record's points.
std::vector<Point> decimate_points(const std::vector<Point>& points, double x_min, double x_max,
                                   std::size_t columns);

/// Time of the last tick of a run (1 when it has fewer than two).
double end_time(const RunRecord& r);
/// "what — the title", or what alone without a title.
std::string title_of(const Options& o, const std::string& what);
/// The SVG's width: options.width_px, at least 400.
double width_of(const Options& o);
/// Pixel columns of the plot area, for decimation (at least 50).
std::size_t columns_of(const Canvas& c);

/// A layer's colour: its name when that is a colour ("#rrggbb"), else one of a palette.
std::string layer_colour(const Options& o, std::size_t layer);
/// The layer of a segment's subpath (0 without layers).
std::size_t layer_of(const Options& o, const BezierSegment& s);

}  // namespace pathstream::host::plot::detail
