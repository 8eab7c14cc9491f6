// The transform attribute: matrix, translate, scale, rotate, skewX, skewY.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {
namespace {

double radians(double degrees) {
    return degrees * std::numbers::pi / 180.0;
}

bool is_name_char(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

struct Kind {
    const char* name;
    std::size_t counts[2];  // accepted argument counts (second 0: only one)
    const char* expected;
};

constexpr Kind kKinds[] = {
    {"matrix", {6, 0}, "6 numbers"},     {"translate", {1, 2}, "1 or 2 numbers"},
    {"scale", {1, 2}, "1 or 2 numbers"}, {"rotate", {1, 3}, "1 or 3 numbers"},
    {"skewX", {1, 0}, "1 number"},       {"skewY", {1, 0}, "1 number"},
};

// The CSS transform property's extra functions.
constexpr Kind kCssKinds[] = {
    {"translateX", {1, 0}, "1 number"}, {"translateY", {1, 0}, "1 number"},
    {"scaleX", {1, 0}, "1 number"},     {"scaleY", {1, 0}, "1 number"},
    {"skew", {1, 2}, "1 or 2 numbers"},
};

bool is_angle(const std::string& name) {
    return name == "rotate" || name == "skewX" || name == "skewY" || name == "skew";
}

// A CSS unit's factor to degrees (angles) or user units (lengths); 0 when not allowed.
double unit_factor(const std::string& function, const std::string& unit) {
    if (unit.empty()) return 1;
    if (is_angle(function)) {
        if (unit == "deg") return 1;
        if (unit == "rad") return 180.0 / std::numbers::pi;
        if (unit == "grad") return 0.9;
        if (unit == "turn") return 360;
        return 0;
    }
    if (function.rfind("translate", 0) != 0) return 0;
    if (unit == "px") return 1;
    if (unit == "mm") return 96.0 / 25.4;
    if (unit == "cm") return 96.0 / 2.54;
    if (unit == "in") return 96.0;
    if (unit == "pt") return 96.0 / 72.0;
    if (unit == "pc") return 16.0;
    return 0;
}

Affine make(const std::string& name, const std::vector<double>& v) {
    if (name == "matrix") return {v[0], v[1], v[2], v[3], v[4], v[5]};
    if (name == "translate") return Affine::translate(v[0], v.size() > 1 ? v[1] : 0.0);
    if (name == "scale") return Affine::scale(v[0], v.size() > 1 ? v[1] : v[0]);
    if (name == "rotate") {
        if (v.size() == 1) return Affine::rotate(v[0]);
        return Affine::translate(v[1], v[2]) * Affine::rotate(v[0]) *
               Affine::translate(-v[1], -v[2]);
    }
    if (name == "skewX") return {1, 0, std::tan(radians(v[0])), 1, 0, 0};
    if (name == "skewY") return {1, std::tan(radians(v[0])), 0, 1, 0, 0};
    if (name == "translateX") return Affine::translate(v[0], 0);
    if (name == "translateY") return Affine::translate(0, v[0]);
    if (name == "scaleX") return Affine::scale(v[0], 1);
    if (name == "scaleY") return Affine::scale(1, v[0]);
    return {1, std::tan(radians(v.size() > 1 ? v[1] : 0.0)), std::tan(radians(v[0])), 1, 0, 0};
}

}  // namespace

Affine Affine::rotate(double degrees) {
    // Exact for multiples of 90 degrees, so rotate(90) maps grid points to grid points.
    const double r = std::fmod(degrees, 360.0);
    double c = 0, s = 0;
    if (r == 0)
        c = 1;
    else if (r == 90 || r == -270)
        s = 1;
    else if (r == 180 || r == -180)
        c = -1;
    else if (r == 270 || r == -90)
        s = -1;
    else
        c = std::cos(radians(r)), s = std::sin(radians(r));
    return {c, s, -s, c, 0, 0};
}

Affine parse_transform(std::string_view text, bool css) {
    Scanner s(text, "transform");
    Affine result;
    s.skip_space();
    if (css) {
        std::string_view rest = text.substr(s.position());
        while (!rest.empty() && (rest.back() == ' ' || rest.back() == '\t' || rest.back() == '\n' ||
                                 rest.back() == '\r' || rest.back() == '\f'))
            rest.remove_suffix(1);
        if (rest == "none") return result;
    }
    bool first = true;
    while (!s.at_end()) {
        if (!first) s.skip_comma_space();
        first = false;
        const std::size_t start = s.position();
        std::string name;
        while (is_name_char(s.peek())) {
            name += s.peek();
            s.advance();
        }
        const Kind* kind = nullptr;
        for (const Kind& k : kKinds) {
            if (name == k.name) kind = &k;
        }
        for (const Kind& k : kCssKinds) {
            if (css && name == k.name) kind = &k;
        }
        if (name.empty()) {
            s.fail(std::string("expected a transform name (matrix, translate, scale, rotate, skewX "
                               "or skewY), found '") +
                       s.peek() + "'",
                   start);
        }
        if (!kind) {
            s.fail("unknown transform '" + name +
                       "' (expected matrix, translate, scale, rotate, skewX or skewY)",
                   start);
        }
        s.skip_space();
        if (s.peek() != '(') s.fail("expected '(' after '" + name + "'", s.position());
        s.advance();
        s.skip_space();
        std::vector<double> args;
        for (;;) {
            if (s.peek() == ')') break;
            if (!args.empty() && s.peek() == ',') {
                s.advance();
                s.skip_space();
            }
            if (s.peek() == '\0') s.fail("expected ')' to close '" + name + "('", s.position());
            if (!s.number_ahead()) {
                s.fail(std::string("expected a number or ')' in '") + name + "(', found '" +
                           s.peek() + "'",
                       s.position());
            }
            args.push_back(s.number("'" + name + "('"));
            if (css) {
                const std::size_t unit_at = s.position();
                std::string unit;
                while (is_name_char(s.peek()) || s.peek() == '%') {
                    unit += s.peek();
                    s.advance();
                }
                const double factor = unit_factor(name, unit);
                if (factor == 0)
                    s.fail("unit '" + unit + "' not allowed in '" + name + "('", unit_at);
                args.back() *= factor;
            }
            s.skip_space();
        }
        s.advance();  // ')'
        if (args.size() != kind->counts[0] &&
            (kind->counts[1] == 0 || args.size() != kind->counts[1])) {
            s.fail(name + " takes " + kind->expected + ", got " + std::to_string(args.size()),
                   start);
        }
        result = result * make(name, args);
    }
    return result;
}

}  // namespace pathstream::host::svg

namespace pathstream::host::svg {
namespace {

// Where a transform-origin keyword puts the origin, as a fraction of the viewport; -1 if none.
double keyword_fraction(std::string_view word, bool& vertical, bool& horizontal) {
    vertical = word == "top" || word == "bottom";
    horizontal = word == "left" || word == "right";
    if (word == "left" || word == "top") return 0;
    if (word == "center") return 0.5;
    if (word == "right" || word == "bottom") return 1;
    return -1;
}

}  // namespace

Point parse_transform_origin(std::string_view text, double width, double height) {
    struct Token {
        std::string_view text;
        std::size_t at;
    };
    std::vector<Token> tokens;
    for (std::size_t i = 0; i < text.size();) {
        while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\n' ||
                                   text[i] == '\r' || text[i] == '\f'))
            ++i;
        const std::size_t start = i;
        while (i < text.size() && text[i] != ' ' && text[i] != '\t' && text[i] != '\n' &&
               text[i] != '\r' && text[i] != '\f')
            ++i;
        if (i == start) break;
        if (tokens.size() == 3) {
            throw ValueError("transform-origin: expected at most 3 values (x y z) at character " +
                             std::to_string(start + 1));
        }
        tokens.push_back({text.substr(start, i - start), start});
    }
    if (tokens.empty()) throw ValueError("transform-origin: expected a value at character 1");
    // Lengths parse with the text before them blanked, so messages count from the value's start.
    const auto value = [&](const Token& t, double base, const char* axis) {
        bool vertical = false, horizontal = false;
        const std::string word(t.text);
        const double f = keyword_fraction(word, vertical, horizontal);
        if (f >= 0) {
            if (std::isnan(base)) {
                throw ValueError("transform-origin: '" + word +
                                 "' needs a viewport size at character " +
                                 std::to_string(t.at + 1));
            }
            return f * base;
        }
        return parse_length(std::string(t.at, ' ') + word, std::string("transform-origin ") + axis,
                            base);
    };
    bool v0 = false, h0 = false, v1 = false, h1 = false;
    const std::string first(tokens[0].text);
    keyword_fraction(first, v0, h0);
    if (tokens.size() == 1) {
        const Token center{"center", tokens[0].at};
        if (v0) return {value(center, width, "x"), value(tokens[0], height, "y")};
        return {value(tokens[0], width, "x"), value(center, height, "y")};
    }
    keyword_fraction(std::string(tokens[1].text), v1, h1);
    if (tokens.size() == 3) value(tokens[2], 0, "z");  // checked, then ignored: no depth in 2D
    if (v0 || h1) {  // "top left": keywords may come in either order
        if (h0 || v1) {
            throw ValueError("transform-origin: '" + std::string(text) +
                             "' puts both values on one axis at character 1");
        }
        return {value(tokens[1], width, "x"), value(tokens[0], height, "y")};
    }
    return {value(tokens[0], width, "x"), value(tokens[1], height, "y")};
}

}  // namespace pathstream::host::svg
