// LinuxCNC's tool table text (docs/formats-gcode.md, "Tool table").
#include "tool_table.hpp"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "cursor.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host::gcode {

namespace {

// One number after a letter: sign, digits, at most one point (as the G-code reader's numbers).
double number(LineCursor& c, char letter) {
    const std::size_t begin = c.i;
    if (c.peek() == '+' || c.peek() == '-') ++c.i;
    bool digits = false, point = false;
    while (!c.done() && (is_digit(c.peek()) || (c.peek() == '.' && !point))) {
        point = point || c.peek() == '.';
        digits = digits || is_digit(c.peek());
        ++c.i;
    }
    if (!digits) c.fail(begin, std::string("missing number after ") + letter);
    std::string text(c.text.substr(begin, c.i - begin));
    if (text[0] == '+') text.erase(0, 1);
    double v = 0;
    const auto r = std::from_chars(text.data(), text.data() + text.size(), v);
    if (r.ec != std::errc() || !std::isfinite(v) || std::fabs(v) > 1e6) {
        c.fail(begin, std::string("value of ") + letter + " is out of range (|value| <= 1e6)");
    }
    return v;
}

}  // namespace

ToolTable ToolTable::parse(const std::string& text, const std::string& file) {
    ToolTable table;
    table.source_ = file;
    std::size_t line_number = 0, at = 0;
    while (at < text.size()) {
        const std::size_t end = std::min(text.find('\n', at), text.size());
        std::string_view line(text.data() + at, end - at);
        at = end + 1;
        ++line_number;
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        LineCursor c{line, line_number, file, 0};
        ToolEntry entry;
        bool has_t = false, any_word = false;
        std::size_t t_at = 0;
        while (true) {
            c.skip_blanks();
            if (c.done()) break;
            if (c.peek() == ';') {
                std::string_view comment = line.substr(c.i + 1);
                while (!comment.empty() && is_blank(comment.front())) comment.remove_prefix(1);
                entry.comment = std::string(comment);
                break;
            }
            const std::size_t word_at = c.i;
            const char letter = upper(c.peek());
            if (!is_letter(c.peek())) {
                c.fail(word_at, "unexpected " + describe_char(c.peek()) +
                                    " (a tool line is words like T1 P1 Z0.5 D3)");
            }
            ++c.i;
            any_word = true;
            const double v = number(c, letter);
            if (letter == 'T' || letter == 'P') {
                if (v != std::floor(v) || v < 0) {
                    c.fail(word_at, std::string(1, letter) + " must be a whole number >= 0");
                }
                (letter == 'T' ? entry.number : entry.pocket) = static_cast<long>(v);
                if (letter == 'T') {
                    has_t = true;
                    t_at = word_at;
                }
            } else if (letter == 'D') {
                if (v < 0) c.fail(word_at, "tool diameter D must not be negative");
                entry.diameter = v;
            } else if (const std::size_t axis = axis_index(letter); axis < kAxisCount) {
                entry.offsets[axis] = v;
            } else if (letter != 'I' && letter != 'J' && letter != 'Q') {
                c.fail(word_at, std::string("unknown tool table word ") + letter +
                                    " (T P X Y Z A B C U V W D I J Q)");
            }
        }
        if (!has_t) {
            if (any_word) c.fail(0, "tool line without T (the tool number)");
            continue;  // blank or a comment
        }
        if (!table.tools_.emplace(entry.number, entry).second) {
            c.fail(t_at, "tool T" + std::to_string(entry.number) + " is given twice");
        }
    }
    return table;
}

ToolTable ToolTable::load(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open tool table");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read tool table");
    return parse(buffer.str(), file);
}

const ToolEntry* ToolTable::find(long number) const {
    const auto it = tools_.find(number);
    return it == tools_.end() ? nullptr : &it->second;
}

}  // namespace pathstream::host::gcode
