// G-code line syntax: words, comments, numbers (docs/formats-gcode.md, "Syntax").
#include "lexer.hpp"

#include <cctype>
#include <charconv>
#include <cstdio>
#include <string_view>

#include "pathstream/host/input_error.hpp"

namespace pathstream::host::gcode {

namespace {

bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}
bool is_digit(char c) {
    return c >= '0' && c <= '9';
}

std::string describe(char c) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x21 && u < 0x7f) return std::string("'") + c + "'";
    char buffer[8];
    std::snprintf(buffer, sizeof buffer, "\\x%02X", u);
    return std::string("byte ") + buffer;
}

class LineLexer {
public:
    LineLexer(std::string_view text, std::size_t line, const std::string& file)
        : text_(text), line_(line), file_(file) {}

    std::optional<Block> block() {
        skip_blanks();
        if (i_ < text_.size() && text_[i_] == '%') return std::nullopt;
        if (i_ < text_.size() && text_[i_] == '/') fail(i_, "block delete '/' is not supported");
        Block b;
        while (true) {
            skip_blanks_and_comments();
            if (i_ >= text_.size() || text_[i_] == ';') break;
            const std::size_t at = i_;
            Word w = word();
            if (b.words.empty() && !seen_n_) b.start = w.at;
            if (w.letter == 'N') {
                if (!b.words.empty() || seen_n_) fail(at, "line number N must start the block");
                seen_n_ = true;
                continue;
            }
            b.words.push_back(std::move(w));
        }
        if (b.words.empty()) return std::nullopt;
        return b;
    }

private:
    [[noreturn]] void fail(std::size_t index, const std::string& message) const {
        throw InputError(file_, SourceLocation{line_, index + 1}, message);
    }

    void skip_blanks() {
        while (i_ < text_.size() && is_blank(text_[i_])) ++i_;
    }

    void skip_blanks_and_comments() {
        while (i_ < text_.size()) {
            if (is_blank(text_[i_])) {
                ++i_;
            } else if (text_[i_] == '(') {
                const auto close = text_.find(')', i_);
                if (close == std::string_view::npos) fail(i_, "unclosed comment '('");
                i_ = close + 1;
            } else {
                return;
            }
        }
    }

    Word word() {
        const std::size_t at = i_;
        const char c = text_[i_];
        if (c == '#') fail(at, "parameters (#) are not supported");
        if (c == '[') fail(at, "expressions ([ ]) are not supported");
        if (!std::isalpha(static_cast<unsigned char>(c))) {
            fail(at,
                 "unexpected character " + describe(c) + " (expected a word: letter and number)");
        }
        const char letter = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        if (letter == 'O') fail(at, "O-words (subroutines and control flow) are not supported");
        if (std::string_view("FGIJMNPQRSTXYZ").find(letter) == std::string_view::npos) {
            fail(at, std::string("unsupported word letter '") + letter +
                         "' (supported: F G I J M N P Q R S T X Y Z)");
        }
        ++i_;
        skip_blanks();
        const std::size_t begin = i_;
        while (i_ < text_.size() &&
               (is_digit(text_[i_]) || text_[i_] == '.' || text_[i_] == '+' || text_[i_] == '-')) {
            ++i_;
        }
        const std::string_view token = text_.substr(begin, i_ - begin);
        if (token.empty()) fail(at, std::string("missing number after ") + letter);
        Word w;
        w.letter = letter;
        w.text = std::string(token);
        w.at = SourceLocation{line_, at + 1};
        w.value = number(token, at, letter);
        return w;
    }

    // [+-] digits [. digits] or [+-] . digits: what LinuxCNC reads, without its expressions.
    double number(std::string_view token, std::size_t at, char letter) const {
        std::size_t k = 0;
        bool negative = false;
        if (token[k] == '+' || token[k] == '-') negative = token[k++] == '-';
        std::size_t digits = 0, points = 0;
        bool nonzero_integer_digit = false;
        for (std::size_t j = k; j < token.size(); ++j) {
            if (is_digit(token[j])) {
                ++digits;
                if (points == 0 && token[j] != '0') nonzero_integer_digit = true;
            } else if (token[j] == '.') {
                ++points;
            } else {
                digits = 0;  // a sign inside the number
                break;
            }
        }
        if (digits == 0 || points > 1) {
            fail(at, "malformed number \"" + std::string(token) + "\" after " + letter);
        }
        const std::string_view body = token.substr(k);
        double value = 0;
        const auto result = std::from_chars(body.data(), body.data() + body.size(), value);
        if (result.ec == std::errc::result_out_of_range) {
            if (nonzero_integer_digit) {
                fail(at, std::string("number after ") + letter +
                             " is out of range (not finite as a double)");
            }
            value = 0;  // underflow: closer to zero than any double
        } else if (result.ec != std::errc() || result.ptr != body.data() + body.size()) {
            fail(at, "malformed number \"" + std::string(token) + "\" after " + letter);
        }
        return negative ? -value : value;
    }

    std::string_view text_;
    std::size_t line_;
    const std::string& file_;
    std::size_t i_ = 0;
    bool seen_n_ = false;
};

}  // namespace

std::optional<Block> lex_line(std::string_view text, std::size_t line_number,
                              const std::string& file) {
    return LineLexer(text, line_number, file).block();
}

}  // namespace pathstream::host::gcode
