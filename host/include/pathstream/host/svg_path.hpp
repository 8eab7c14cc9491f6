// Reader of SVG drawings (docs/formats-svg.md): every path and basic shape becomes open cubic
// Bezier subpaths in millimetres, y downward as in SVG.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
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
/// subpaths left empty. Strokes are cut at their clip-path and at nested <svg>/<symbol>
/// viewports (a cut piece becomes straight pieces within `tolerance_mm`); elements failing
/// their systemLanguage ("en" passes) or requiredExtensions test are not drawn. What is not
/// drawn or not applied (text, images, masks, filters, markers, clips that cannot be applied)
/// goes to info->warnings, one line per kind.
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
    /// What was not drawn or not applied ("file:line:col: what"), one line per kind with a
    /// count and the first place: text, images, masks, filters, markers, pattern fills, clips
    /// that cannot be applied (docs/formats-svg.md, "Warnings").
    std::vector<std::string> warnings;
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
    std::size_t begin_ = 0;                    // after the byte order mark
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

/// One CSS declaration `name: value` and where it is in the text it was parsed from.
struct CssDeclaration {
    std::string name;   // lower-cased
    std::string value;  // trimmed, without "!important", as written
    bool important = false;
    std::size_t name_offset = 0;   // byte offset of the name
    std::size_t value_offset = 0;  // byte offset of the value's first character
};

/// Malformed CSS that error recovery cannot skip (an unclosed comment or block, too many
/// rules): the message and the byte offset of the problem in the text parsed.
class CssError : public std::runtime_error {
public:
    CssError(const std::string& what, std::size_t at) : std::runtime_error(what), offset(at) {}
    std::size_t offset;
};

/// Parses a declaration list (a style attribute, a rule's block); `base` is added to the
/// offsets. As CSS error recovery says, a declaration without ':' or a name is dropped, and
/// comments count as whitespace. Throws CssError on an unclosed comment.
std::vector<CssDeclaration> parse_css_declarations(std::string_view text, std::size_t base = 0);

/// The rules of a document's <style> elements, for the properties the reader uses (display,
/// visibility, stroke, transform, transform-origin, clip-path, clip-rule, overflow, and mask,
/// filter, marker*, fill for its warnings). A selector is a compound of an optional
/// type (or *) and any number of .class and #id; selector lists are split into one rule per
/// selector. Other selectors (combinators, attributes, pseudo-classes, escapes) never match;
/// at-rules (@media, @import, ...) are skipped with their blocks.
class StyleSheet {
public:
    /// Rules per document, counting every selector of a list: more are refused.
    static constexpr std::size_t kMaxRules = 10000;
    /// Properties the sheet keeps declarations of (the others are dropped when read).
    static constexpr std::size_t kProperties = 15;

    /// Adds the rules of one style sheet text whose first byte is at `base` in the document.
    /// Throws CssError on an unclosed comment or block, a '}' without a rule, or more than
    /// kMaxRules rules in all.
    void add(std::string_view css, std::size_t base = 0);
    /// The winning declaration of each property (normal and !important apart) among the rules
    /// matching an element of this type, id and class attribute, by specificity (id > class >
    /// type), then document order; at most one per property and importance.
    std::vector<const CssDeclaration*> match(std::string_view type, std::string_view id,
                                             std::string_view classes) const;
    /// Rules read, including those whose selectors never match.
    std::size_t rules() const { return count_; }
    /// True when no rule can match anything.
    bool empty() const { return rules_.empty(); }

private:
    // One distinct selector; rules repeating it are merged, each declaration keeping its
    // document order, so a sheet repeating one selector costs one candidate per element.
    struct Slot {
        const CssDeclaration* declaration = nullptr;
        std::size_t order = 0;
    };
    struct Rule {
        std::string type;  // "" for any
        std::string id;
        std::vector<std::string> classes;
        std::uint32_t specificity = 0;
        std::array<std::array<Slot, 2>, kProperties>
            slots{};  // per used property, normal and !important
    };
    void add_rule(std::string_view selector, std::size_t block);

    std::vector<std::vector<CssDeclaration>> blocks_;
    std::vector<Rule> rules_;
    std::unordered_map<std::string, std::size_t> by_selector_;  // canonical selector -> rule
    std::size_t count_ = 0;
    std::size_t declarations_ = 0;  // document order of declarations
    // Each rule is indexed once, by its id, else its first class, else its type, else "*".
    std::unordered_map<std::string, std::vector<std::size_t>> by_id_, by_class_, by_type_;
};

/// Parses a transform attribute: a list of matrix(a b c d e f), translate(x [y]),
/// scale(x [y]), rotate(a [cx cy]), skewX(a), skewY(a), separated by whitespace or commas;
/// angles in degrees. Returns their product (the leftmost applied last). Empty text is the
/// identity. Throws ValueError "transform: ..." on anything else.
/// With `css`, the CSS transform property's syntax too: "none", translateX/Y, scaleX/Y,
/// skew(ax [ay]), and units on numbers (lengths: px mm cm in pt pc; angles: deg rad grad turn).
Affine parse_transform(std::string_view text, bool css = false);

/// Parses transform-origin ("x [y [z]]": lengths, percentages of `width` / `height` (NaN:
/// no viewport, an error), keywords left center right top bottom; z is ignored) into a point
/// in user units. Throws ValueError "transform-origin: ...".
Point parse_transform_origin(std::string_view text, double width, double height);

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
