// A read position in one line of G-code, shared by the lexer, the expression reader and the
// O-word reader so that every error names the same file:line:col.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include "pathstream/host/path.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host::gcode {

/// Blanks between words (a line break never reaches the lexer).
inline bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
inline bool is_digit(char c) {
    return c >= '0' && c <= '9';
}
inline bool is_letter(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}
inline char upper(char c) {
    return c >= 'a' && c <= 'z' ? static_cast<char>(c - 'a' + 'A') : c;
}

/// "'@'" for a printable character, "byte \x01" for others.
std::string describe_char(char c);

/// One line being read: the text, where it is, and how far reading has got.
struct LineCursor {
    std::string_view text;
    std::size_t line = 0;  ///< 1-based
    const std::string& file;
    std::size_t i = 0;  ///< index of the next character

    bool done() const { return i >= text.size(); }
    char peek() const { return done() ? '\0' : text[i]; }
    /// Skips blanks (not comments).
    void skip_blanks() {
        while (!done() && is_blank(text[i])) ++i;
    }
    /// Location of character `index` (1-based column).
    SourceLocation at(std::size_t index) const { return SourceLocation{line, index + 1}; }
    /// Throws InputError "file:line:col: message" at character `index`.
    [[noreturn]] void fail(std::size_t index, const std::string& message) const {
        throw InputError(file, at(index), message);
    }
};

}  // namespace pathstream::host::gcode
