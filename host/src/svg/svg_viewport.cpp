// Lengths with units, and the viewBox to viewport map.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {

double parse_length(std::string_view text, const std::string& what, double percent_base) {
    Scanner s(text, what);
    s.skip_space();
    if (!s.number_ahead()) {
        s.fail(std::string("expected a length (a number with an optional unit), found '") +
                   std::string(text.substr(s.position())) + "'",
               s.position());
    }
    const double value = s.number("'" + what + "='");
    const std::size_t unit_at = s.position();
    std::string unit;
    while ((s.peek() >= 'a' && s.peek() <= 'z') || (s.peek() >= 'A' && s.peek() <= 'Z') ||
           s.peek() == '%') {
        unit += s.peek();
        s.advance();
    }
    if (!s.at_end())
        s.fail(std::string("unexpected '") + s.peek() + "' after the length", s.position());
    if (unit.empty() || unit == "px") return value;
    if (unit == "mm") return value * 96.0 / 25.4;
    if (unit == "cm") return value * 96.0 / 2.54;
    if (unit == "in") return value * 96.0;
    if (unit == "pt") return value * 96.0 / 72.0;
    if (unit == "pc") return value * 16.0;
    if (unit == "%") {
        if (std::isnan(percent_base)) {
            s.fail(
                "a percentage needs a viewport size (give the <svg> a viewBox or a width and "
                "height)",
                unit_at);
        }
        return value / 100.0 * percent_base;
    }
    s.fail("unknown unit '" + unit + "' (expected mm, cm, in, pt, pc, px, % or none)", unit_at);
}

Affine viewbox_transform(const std::array<double, 4>& view_box, double width, double height,
                         std::string_view preserve_aspect_ratio) {
    std::istringstream words{std::string(preserve_aspect_ratio)};
    std::string align = "xMidYMid", mode = "meet", word, extra;
    if (words >> word) {
        if (word == "defer") words >> word;
        align = word;
        if (words >> word) mode = word;
    }
    static const char* const kAligns[] = {"none",     "xMinYMin", "xMidYMin", "xMaxYMin",
                                          "xMinYMid", "xMidYMid", "xMaxYMid", "xMinYMax",
                                          "xMidYMax", "xMaxYMax"};
    bool known = false;
    for (const char* a : kAligns) known = known || align == a;
    if (!known || (mode != "meet" && mode != "slice") || (words >> extra)) {
        throw ValueError("preserveAspectRatio: unknown value '" +
                         std::string(preserve_aspect_ratio) +
                         "' (expected none or xMinYMin ... xMaxYMax, then meet or slice)");
    }
    const auto [vx, vy, vw, vh] = view_box;
    double sx = width / vw, sy = height / vh;
    if (align == "none") return {sx, 0, 0, sy, -vx * sx, -vy * sy};
    sx = sy = mode == "slice" ? std::max(sx, sy) : std::min(sx, sy);
    double tx = -vx * sx, ty = -vy * sy;
    const std::string x = align.substr(1, 3), y = align.substr(5, 3);
    if (x == "Mid") tx += (width - vw * sx) / 2;
    if (x == "Max") tx += width - vw * sx;
    if (y == "Mid") ty += (height - vh * sy) / 2;
    if (y == "Max") ty += height - vh * sy;
    return {sx, 0, 0, sy, tx, ty};
}

}  // namespace pathstream::host::svg
