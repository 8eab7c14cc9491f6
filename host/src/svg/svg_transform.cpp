// The transform attribute: matrix, translate, scale, rotate, skewX, skewY.
#include <cmath>
#include <numbers>

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
    return {1, std::tan(radians(v[0])), 0, 1, 0, 0};  // skewY
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

Affine parse_transform(std::string_view text) {
    Scanner s(text, "transform");
    Affine result;
    s.skip_space();
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
