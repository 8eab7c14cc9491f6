// G-code line syntax: words, comments, parameter settings (docs/formats-gcode.md, "Syntax").
#include "lexer.hpp"

#include "cursor.hpp"
#include "expression.hpp"

namespace pathstream::host::gcode {

namespace {

class LineLexer {
public:
    LineLexer(std::string_view text, std::size_t line, const std::string& file,
              const Parameters& parameters)
        : c_{text, line, file, 0}, parameters_(parameters) {}

    std::optional<Block> block() {
        c_.skip_blanks();
        if (c_.peek() == '%') return std::nullopt;
        if (c_.peek() == '/') c_.fail(c_.i, "block delete '/' is not supported");
        Block b;
        if (c_.peek() == '$') {
            b.dollar = true;
            b.start = c_.at(c_.i);
            return b;
        }
        while (true) {
            skip_blanks_and_comments();
            if (c_.done() || c_.peek() == ';') break;
            if (c_.peek() == '*') {
                checksum();
                break;
            }
            if (c_.peek() == '#') {
                if (b.words.empty() && b.assignments.empty() && !seen_n_) b.start = c_.at(c_.i);
                b.assignments.push_back(assignment());
                continue;
            }
            const std::size_t at = c_.i;
            Word w = word();
            if (b.words.empty() && b.assignments.empty() && !seen_n_) b.start = w.at;
            if (w.letter == 'N') {
                if (!b.words.empty() || !b.assignments.empty() || seen_n_) {
                    c_.fail(at, "line number N must start the block");
                }
                seen_n_ = true;
                continue;
            }
            b.words.push_back(std::move(w));
        }
        if (b.words.empty() && b.assignments.empty()) return std::nullopt;
        return b;
    }

private:
    void skip_blanks_and_comments() {
        while (!c_.done()) {
            if (is_blank(c_.peek())) {
                ++c_.i;
            } else if (c_.peek() == '(') {
                const auto close = c_.text.find(')', c_.i);
                if (close == std::string_view::npos) c_.fail(c_.i, "unclosed comment '('");
                c_.i = close + 1;
            } else {
                return;
            }
        }
    }

    // "*nn" as senders append it (RepRap, Marlin): the XOR of every byte before the '*'. Only
    // blanks and comments may follow.
    void checksum() {
        const std::size_t star = c_.i;
        ++c_.i;
        c_.skip_blanks();
        const std::size_t begin = c_.i;
        unsigned value = 0;
        while (!c_.done() && is_digit(c_.peek()) && c_.i - begin < 4) {
            value = value * 10 + static_cast<unsigned>(c_.peek() - '0');
            ++c_.i;
        }
        if (c_.i == begin || value > 255) c_.fail(star, "a checksum '*' needs a number 0..255");
        unsigned expected = 0;
        for (std::size_t k = 0; k < star; ++k) expected ^= static_cast<unsigned char>(c_.text[k]);
        if (value != expected) {
            c_.fail(star, "checksum *" + std::to_string(value) + " does not match the line (*" +
                              std::to_string(expected) + ")");
        }
        skip_blanks_and_comments();
        if (!c_.done() && c_.peek() != ';') {
            c_.fail(c_.i, "unexpected " + describe_char(c_.peek()) + " after the checksum");
        }
    }

    // "#ref = value"; the reference's own expression is read with the old values too.
    Assignment assignment() {
        Assignment a;
        a.at = c_.at(c_.i);
        a.target = read_parameter_ref(c_, parameters_);
        c_.skip_blanks();
        if (c_.peek() != '=') {
            c_.fail(c_.i, "expected '=' after " + parameter_text(a.target) +
                              " (a parameter is read only inside a value)");
        }
        ++c_.i;
        a.value = read_value(c_, parameters_, 0);
        return a;
    }

    Word word() {
        const std::size_t at = c_.i;
        const char ch = c_.peek();
        if (!is_letter(ch) && ch != '@' && ch != '^') {
            c_.fail(at, "unexpected character " + describe_char(ch) +
                            " (expected a word: letter and number)");
        }
        const char letter = upper(ch);
        if (letter == 'O') c_.fail(at, "an O-word must be the first word of its line");
        ++c_.i;
        c_.skip_blanks();
        if (c_.done() || c_.peek() == ';' || c_.peek() == '(') {
            c_.fail(at, std::string("missing number after ") + letter);
        }
        const std::size_t begin = c_.i;
        Word w;
        w.letter = letter;
        w.at = c_.at(at);
        w.value = read_value(c_, parameters_, letter, at);
        w.text = std::string(c_.text.substr(begin, c_.i - begin));
        return w;
    }

    LineCursor c_;
    const Parameters& parameters_;
    bool seen_n_ = false;
};

}  // namespace

std::optional<Block> lex_line(std::string_view text, std::size_t line_number,
                              const std::string& file, const Parameters& parameters) {
    return LineLexer(text, line_number, file, parameters).block();
}

}  // namespace pathstream::host::gcode
