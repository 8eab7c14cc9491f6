// The SVG number grammar, shared by path data, transforms, viewBox and points lists.
#include <charconv>
#include <cmath>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {
namespace {

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f';
}
bool is_digit(char c) {
    return c >= '0' && c <= '9';
}

}  // namespace

void Scanner::skip_space() {
    while (pos_ < text_.size() && is_space(text_[pos_])) ++pos_;
}

void Scanner::skip_comma_space() {
    skip_space();
    if (peek() == ',') {
        ++pos_;
        skip_space();
    }
}

bool Scanner::at_end() {
    skip_space();
    return pos_ >= text_.size();
}

bool Scanner::number_ahead() const {
    const char c = peek();
    return is_digit(c) || c == '.' || c == '-' || c == '+';
}

double Scanner::number(const std::string& after) {
    const std::size_t start = pos_;
    std::size_t i = pos_;
    const auto at = [&](std::size_t k) { return k < text_.size() ? text_[k] : '\0'; };
    if (at(i) == '+' || at(i) == '-') ++i;
    std::size_t digits = 0;
    while (is_digit(at(i))) ++i, ++digits;
    if (at(i) == '.') {
        ++i;
        while (is_digit(at(i))) ++i, ++digits;
    }
    if (digits == 0) fail("expected a number after " + after, start);
    if (at(i) == 'e' || at(i) == 'E') {
        std::size_t k = i + 1;
        if (at(k) == '+' || at(k) == '-') ++k;
        if (is_digit(at(k))) {
            while (is_digit(at(k))) ++k;
            i = k;
        }
    }
    pos_ = i;
    const std::string_view token = text_.substr(start, i - start);
    const std::size_t skip = token.front() == '+' ? 1 : 0;  // from_chars takes no '+'
    double value = 0;
    const auto [end, ec] = std::from_chars(token.data() + skip, token.data() + token.size(), value);
    if (ec == std::errc::result_out_of_range) {
        // Too small underflows to zero; too large is an error.
        const auto e = token.find_first_of("eE");
        if (e != std::string_view::npos && token.size() > e + 1 && token[e + 1] == '-') return 0.0;
        fail("number '" + std::string(token) + "' is out of range (not finite)", start);
    }
    if (ec != std::errc{} || end != token.data() + token.size() || !std::isfinite(value)) {
        fail("number '" + std::string(token) + "' is out of range (not finite)", start);
    }
    return value;
}

bool Scanner::flag(const std::string& after) {
    const char c = peek();
    if (c != '0' && c != '1') fail("expected a flag (0 or 1) after " + after, pos_);
    ++pos_;
    return c == '1';
}

void Scanner::fail(const std::string& message, std::size_t at) const {
    throw ValueError(what_ + ": " + message + " at character " + std::to_string(at + 1));
}

std::vector<double> parse_number_list(std::string_view text, const std::string& what) {
    Scanner s(text, what);
    std::vector<double> out;
    s.skip_space();
    while (!s.at_end()) {
        if (!s.number_ahead())
            s.fail(std::string("expected a number, found '") + s.peek() + "'", s.position());
        out.push_back(s.number("'" + what + "='"));
        s.skip_comma_space();
    }
    return out;
}

}  // namespace pathstream::host::svg
