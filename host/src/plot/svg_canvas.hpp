// Private helpers of the plot writers: an SVG document with a data-to-pixel mapping, nice
// axis ticks, legends. Not part of the host library's interface.
#pragma once

#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include "pathstream/host/plot.hpp"

namespace pathstream::host::plot::detail {

/// Text safe inside XML content and attribute values.
std::string xml_escape(const std::string& text);

/// A short decimal for axis labels and figures: `decimals` places, no "-0".
std::string format_number(double value, int decimals);

/// Tick positions 1/2/5 x 10^n covering [lo, hi] with about `target` ticks, and the decimals
/// that print them without loss.
struct Ticks {
    std::vector<double> values;
    int decimals = 0;
};
Ticks nice_ticks(double lo, double hi, int target);

/// Colours of axis i (cycled), and the fixed series colours.
const char* axis_colour(std::size_t axis);
inline constexpr const char* kIdealColour = "#b8b8b8";
inline constexpr const char* kSetpointColour = "#1f5fbf";
inline constexpr const char* kPlantColour = "#d9480f";
inline constexpr const char* kFeedColour = "#2b8a3e";

/// One legend entry: a line swatch (dash pattern optional, width) and a label.
struct LegendEntry {
    std::string label;
    std::string colour;
    std::string dash;  ///< SVG stroke-dasharray, empty for solid
    double width = 2;
};

/// An SVG document with one rectangular plot area mapping data [x0, x1] x [y0, y1] onto it.
/// y_down: data y grows downwards on screen (the path's own SVG-like orientation).
class Canvas {
public:
    Canvas(double width, double height, double left, double top, double right, double bottom);

    void set_range(double x0, double x1, double y0, double y1, bool y_down);
    double px(double x) const { return left_ + (x - x0_) * sx_; }
    double py(double y) const { return y_down_ ? top_ + (y - y0_) * sy_ : top_ + (y1_ - y) * sy_; }
    double plot_left() const { return left_; }
    double plot_top() const { return top_; }
    double plot_width() const { return width_ - left_ - right_; }
    double plot_height() const { return height_ - top_ - bottom_; }
    double x0() const { return x0_; }
    double x1() const { return x1_; }
    double y0() const { return y0_; }
    double y1() const { return y1_; }

    std::ostringstream& body() { return body_; }

    /// Title (top left) and a legend row under it.
    void title(const std::string& text);
    void legend(const std::vector<LegendEntry>& entries);
    /// Frame, grid, ticks with labels, axis titles.
    void axes(const std::string& x_label, const std::string& y_label);
    /// Opens a group clipped to the plot area; close with end_group().
    void begin_series(const std::string& id);
    void end_group() { body_ << "</g>\n"; }
    /// A polyline of data points (converted to pixels here).
    void polyline(const std::vector<Point>& data, const std::string& colour, double width,
                  const std::string& dash = {}, const std::string& cls = {});
    /// A polyline already in pixels.
    void polyline_px(const std::vector<Point>& pixels, const std::string& colour, double width,
                     const std::string& dash = {}, const std::string& cls = {});
    /// Horizontal line across the plot at data y, with an optional label at its right end.
    void hline(double y, const std::string& colour, const std::string& dash, const std::string& id,
               const std::string& label = {});
    /// Vertical band [x_from, x_to] in data x (shading).
    void band(double x_from, double x_to, const std::string& fill, const std::string& cls);
    /// A small note at the bottom left (below the x axis title).
    void note(const std::string& text);

    std::string finish();

private:
    double width_, height_, left_, top_, right_, bottom_;
    double x0_ = 0, x1_ = 1, y0_ = 0, y1_ = 1, sx_ = 1, sy_ = 1;
    bool y_down_ = false;
    std::ostringstream head_;
    std::ostringstream body_;
    std::string title_;
    std::vector<LegendEntry> legend_;
    std::vector<std::string> notes_;
};

}  // namespace pathstream::host::plot::detail
