// Reader of SVG drawings (docs/formats-svg.md): every path and basic shape becomes open cubic
// Bezier subpaths in millimetres, y downward as in SVG.
#pragma once

#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

namespace svg {
struct SvgReadInfo;
}

/// Parses an SVG document. `file` names the source in error messages.
/// Returns a Path with axes = 2 whose subpaths are open Bezier chains (P0 C C P1 C C P2 ...,
/// 3k + 1 points, basis kBezier, closed = false, feed 0), one per SVG subpath or shape, in
/// document order, in millimetres in the root user coordinate system after every transform,
/// the viewBox and the units (x to the right, y downward). Lines are exact cubics with control
/// points at 1/3 and 2/3; quadratics are degree-elevated exactly; elliptical arcs, circles and
/// ellipses are approximated within `tolerance_mm` (measured in mm after all transforms).
/// Pieces whose four points lie within 1e-9 mm of each other are dropped, and so are
/// subpaths left empty.
/// Throws InputError ("file:line:col: what is wrong") on malformed XML, a root that is not
/// <svg>, bad path data, transforms, lengths, units, viewBox or points lists, non-finite
/// numbers, negative sizes, coordinates beyond 1e6 mm, and a document without drawable
/// geometry ("no drawable paths"). `tolerance_mm` must be positive and finite (else InputError
/// without a location).
/// When `info` is given, it receives what the read found and cost beyond the path.
Path parse_svg_path(const std::string& text, const std::string& file, double tolerance_mm = 0.01,
                    svg::SvgReadInfo* info = nullptr);

/// Reads and parses an SVG file as parse_svg_path does. Throws InputError, also when the file
/// cannot be opened or read.
Path load_svg_path(const std::string& file, double tolerance_mm = 0.01);

/// Building blocks of the SVG reader, exposed for its tests. Coordinates are in SVG user units
/// unless a name says mm.
namespace svg {

/// What one read found beside the geometry, and what it cost (tests and benches check that
/// reading stays linear in the document's size).
struct SvgReadInfo {
    /// The computed CSS `stroke` of each subpath's element, parallel to Path::subpaths
    /// (lower-cased as written, "none" when unset), for a later split by colour.
    std::vector<std::string> strokes;
    /// Bytes the line:column lookups scanned, building the index excluded.
    std::size_t location_bytes_scanned = 0;
    /// Line:column lookups made.
    std::size_t locations = 0;
    /// Rules read from <style> elements (one per selector of a selector list).
    std::size_t style_rules = 0;
};

/// Line and column (1-based; columns count UTF-8 characters; a leading byte order mark does
/// not count) of byte offsets in one text. One pass at construction records the place of every
/// kStride-th byte, so each lookup scans fewer than kStride bytes whatever the text's size.
class TextLocator {
public:
    static constexpr std::size_t kStride = 256;

    /// Indexes `text`, which must outlive the locator.
    explicit TextLocator(std::string_view text);
    /// The place of byte `offset` (clamped to the text's end).
    SourceLocation locate(std::size_t offset);
    /// Bytes scanned by locate() so far.
    std::size_t bytes_scanned() const { return scanned_; }
    /// Calls of locate() so far.
    std::size_t lookups() const { return lookups_; }

private:
    std::string_view text_;
    std::size_t begin_ = 0;                   // after the byte order mark
    std::vector<SourceLocation> checkpoints_;  // place of byte k * kStride
    std::size_t scanned_ = 0;
    std::size_t lookups_ = 0;
};

/// A point in the plane.
struct Point {
    double x = 0;
    double y = 0;
    friend bool operator==(const Point&, const Point&) = default;
};

/// One cubic Bezier piece: start, first control, second control, end.
using Cubic = std::array<Point, 4>;

/// Cubic pieces grouped by subpath (each inner list is one connected chain: piece i + 1 starts
/// where piece i ends). An inner list may be empty (e.g. a lone moveto).
using CubicSubpaths = std::vector<std::vector<Cubic>>;

/// A problem inside one attribute value. what() is the message without a place, e.g.
/// "path data: expected a number after 'C' at character 17"; the reader prefixes
/// "file:line:col: " with the attribute's position.
class ValueError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// An affine map (x, y) -> (a x + c y + e, b x + d y + f): SVG's matrix(a b c d e f).
struct Affine {
    double a = 1, b = 0, c = 0, d = 1, e = 0, f = 0;

    /// The image of `p`.
    Point operator()(Point p) const { return {a * p.x + c * p.y + e, b * p.x + d * p.y + f}; }

    /// The map that applies `inner` first, then this one.
    Affine operator*(const Affine& inner) const {
        return {a * inner.a + c * inner.b,     b * inner.a + d * inner.b,
                a * inner.c + c * inner.d,     b * inner.c + d * inner.d,
                a * inner.e + c * inner.f + e, b * inner.e + d * inner.f + f};
    }

    /// Determinant of the linear part; 0 for a map that collapses the plane.
    double determinant() const { return a * d - b * c; }

    /// translate(tx ty), scale(sx sy), rotate(degrees) about the origin.
    static Affine translate(double tx, double ty) { return {1, 0, 0, 1, tx, ty}; }
    static Affine scale(double sx, double sy) { return {sx, 0, 0, sy, 0, 0}; }
    static Affine rotate(double degrees);
};

/// A cursor over one attribute value that reads the SVG number grammar
/// (sign? (digits ('.' digits?)? | '.' digits) exponent?, so "-.5.5" is -0.5 then 0.5),
/// arc flags and comma/whitespace separators. Messages name `what` and a 1-based character
/// position in the value: "<what>: <message> at character N".
class Scanner {
public:
    /// Scans `text`; `what` prefixes messages ("path data", "transform", "points", ...).
    Scanner(std::string_view text, std::string what) : text_(text), what_(std::move(what)) {}

    /// Skips SVG whitespace (space, tab, CR, LF, FF).
    void skip_space();
    /// Skips whitespace, at most one comma, and whitespace again.
    void skip_comma_space();
    /// True when only whitespace is left.
    bool at_end();
    /// True when the next character (no skipping) can start a number.
    bool number_ahead() const;
    /// Reads a number at the cursor (no skipping). Throws ValueError "expected a number after
    /// <after>" when none is there, "number '1e999' is out of range (not finite)" on overflow.
    double number(const std::string& after);
    /// Reads one arc flag '0' or '1' (no skipping); throws "expected a flag (0 or 1) after ...".
    bool flag(const std::string& after);
    /// The next character (no skipping), or '\0' at the end.
    char peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
    /// Consumes one character.
    void advance() { ++pos_; }
    /// 0-based position of the cursor.
    std::size_t position() const { return pos_; }
    /// Throws ValueError "<what>: <message> at character <at + 1>".
    [[noreturn]] void fail(const std::string& message, std::size_t at) const;

private:
    std::string_view text_;
    std::string what_;
    std::size_t pos_ = 0;
};

/// Parses a whitespace/comma separated list of numbers (viewBox, points). Throws ValueError
/// prefixed with `what`.
std::vector<double> parse_number_list(std::string_view text, const std::string& what);

/// Parses a transform attribute: a list of matrix(a b c d e f), translate(x [y]),
/// scale(x [y]), rotate(a [cx cy]), skewX(a), skewY(a), separated by whitespace or commas;
/// angles in degrees. Returns their product (the leftmost applied last). Empty text is the
/// identity. Throws ValueError "transform: ..." on anything else.
Affine parse_transform(std::string_view text);

/// Parses a length: a number with an optional unit mm, cm, in, pt, pc, px or % (none: px;
/// 96 px per inch), and returns it in px. `percent_base` is the value of 100% in px; NaN when
/// there is none (percentages are then an error). Throws ValueError prefixed with `what`.
double parse_length(std::string_view text, const std::string& what, double percent_base);

/// The map of a viewBox {min-x, min-y, width, height} (width, height > 0) onto the viewport
/// [0, width] x [0, height] as `preserve_aspect_ratio` says ("[defer] <align> [meet | slice]",
/// align none or xMinYMin ... xMaxYMax; empty: xMidYMid meet). Throws ValueError
/// "preserveAspectRatio: ..." on an unknown value.
Affine viewbox_transform(const std::array<double, 4>& view_box, double width, double height,
                         std::string_view preserve_aspect_ratio);

/// The straight piece from `from` to `to` as a cubic with control points at 1/3 and 2/3.
Cubic line_cubic(Point from, Point to);

/// The quadratic Bezier (from, control, to) raised exactly to a cubic.
Cubic quadratic_cubic(Point from, Point control, Point to);

/// The arc of the ellipse centred at `center` with radii rx, ry (> 0) and x axis rotated by
/// `phi_radians`, from parameter angle theta1 over delta (radians, either sign), as cubic
/// pieces of at most 90 degrees each, split further until each piece, mapped by `to_mm`,
/// deviates at most `tolerance_mm` from the mapped ellipse (checked at sample points).
std::vector<Cubic> ellipse_arc_cubics(Point center, double rx, double ry, double phi_radians,
                                      double theta1, double delta, const Affine& to_mm,
                                      double tolerance_mm);

/// SVG's elliptical arc command (path data 'A', angle in degrees) from `from` to `to`, per the
/// SVG 2 implementation notes: no pieces when the end points are equal, one straight piece
/// when rx or ry is 0, radii made absolute and scaled up when too small to reach `to`.
/// The first piece starts exactly at `from`, the last ends exactly at `to`.
std::vector<Cubic> arc_to_cubics(Point from, double rx, double ry, double angle_degrees,
                                 bool large_arc, bool sweep, Point to, const Affine& to_mm,
                                 double tolerance_mm);

/// Parses path data (a d attribute): every command of SVG 2 (M L H V C S Q T A Z, absolute
/// and relative, with implicit repetition and S/T reflection). One inner list per subpath;
/// after Z the next drawing command starts a new subpath at the same start point. Arcs are
/// approximated as arc_to_cubics does with `to_mm` and `tolerance_mm`. Throws ValueError
/// "path data: ..." on any syntax error.
CubicSubpaths parse_path_data(std::string_view d, const Affine& to_mm, double tolerance_mm);

/// The outline of an ellipse (a circle when rx = ry) as SVG 2 draws it: four quarter arcs
/// starting at (cx + rx, cy) in the positive angle direction (clockwise with y down).
std::vector<Cubic> ellipse_cubics(Point center, double rx, double ry, const Affine& to_mm,
                                  double tolerance_mm);

/// The outline of a rectangle with corner radii rx, ry (already resolved and clamped to
/// half the width and height), as SVG 2 draws it: from (x + rx, y) clockwise.
std::vector<Cubic> rect_cubics(double x, double y, double width, double height, double rx,
                               double ry, const Affine& to_mm, double tolerance_mm);

/// Straight pieces through `points`, back to the first point when `closed`.
std::vector<Cubic> polyline_cubics(const std::vector<Point>& points, bool closed);

}  // namespace svg
}  // namespace pathstream::host
