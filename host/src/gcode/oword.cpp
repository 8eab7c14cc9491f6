// O-word statements and their pairing (docs/formats-gcode.md, "O-words").
#include "oword.hpp"

#include "cursor.hpp"

namespace pathstream::host::gcode {

namespace {

struct KeywordName {
    const char* name;
    OKind kind;
};
constexpr KeywordName kKeywords[] = {
    {"sub", OKind::kSub},
    {"endsub", OKind::kEndsub},
    {"call", OKind::kCall},
    {"return", OKind::kReturn},
    {"if", OKind::kIf},
    {"elseif", OKind::kElseif},
    {"else", OKind::kElse},
    {"endif", OKind::kEndif},
    {"while", OKind::kWhile},
    {"endwhile", OKind::kEndwhile},
    {"do", OKind::kDo},
    {"repeat", OKind::kRepeat},
    {"endrepeat", OKind::kEndrepeat},
    {"break", OKind::kBreak},
    {"continue", OKind::kContinue},
};

constexpr std::size_t kMaxNesting = 1000;  // open blocks at once: bounds the label searches

bool is_loop(OKind k) {
    return k == OKind::kWhile || k == OKind::kDo || k == OKind::kRepeat;
}

class StructureScanner {
public:
    StructureScanner(const std::vector<std::string_view>& lines, const std::string& file)
        : lines_(lines), file_(file) {}

    ProgramStructure scan() {
        for (std::size_t k = 0; k < lines_.size(); ++k) {
            std::optional<OLine> found = scan_oword(lines_[k], k + 1, file_);
            if (!found) continue;
            const OLine& o = s_.olines.emplace(k, std::move(*found)).first->second;
            statement(k, o);
            if (open_.size() > kMaxNesting) {
                fail(o, "O-word blocks nested more than " + std::to_string(kMaxNesting) + " deep");
            }
        }
        if (!open_.empty()) {
            const OLine& o = line(open_.back());
            fail(o, oline_text(o) + " is never closed (no " + closer(o.kind) + ")");
        }
        return std::move(s_);
    }

private:
    [[noreturn]] void fail(const OLine& o, const std::string& message) const {
        throw InputError(file_, o.at, message);
    }

    static std::string closer(OKind k) {
        switch (k) {
            case OKind::kSub:
                return "endsub";
            case OKind::kIf:
                return "endif";
            case OKind::kWhile:
                return "endwhile";
            case OKind::kDo:
                return "while";
            default:
                return "endrepeat";
        }
    }

    OLine& line(std::size_t k) { return s_.olines.at(k); }
    const OLine& open_line(std::size_t i) const { return s_.olines.at(open_[i]); }

    // The innermost open statement must be `kind` with the label of `o`.
    std::size_t close(std::size_t k, const OLine& o, OKind kind) {
        if (open_.empty() || open_line(open_.size() - 1).kind != kind ||
            open_line(open_.size() - 1).label != o.label) {
            std::string message = oline_text(o) + " without an open O";
            message += (o.label.empty() || is_digit(o.label[0]) ? o.label : "<" + o.label + ">");
            message += std::string(" ") + okind_name(kind);
            if (!open_.empty()) {
                const OLine& top = open_line(open_.size() - 1);
                message += " (the innermost open block is " + oline_text(top) + " on line " +
                           std::to_string(top.at.line) + ")";
            }
            fail(o, message);
        }
        const std::size_t opener = open_.back();
        if (kind != OKind::kIf) open_.pop_back();
        line(opener).partner = k;
        line(k).partner = opener;
        return opener;
    }

    void statement(std::size_t k, const OLine& o) {
        switch (o.kind) {
            case OKind::kSub:
                if (!open_.empty())
                    fail(o, oline_text(o) +
                                " inside another block (define subroutines at the top level)");
                if (!s_.subs.emplace(o.label, k).second)
                    fail(o, oline_text(o) + " is defined twice");
                open_.push_back(k);
                break;
            case OKind::kEndsub:
                close(k, o, OKind::kSub);
                break;
            case OKind::kReturn:
                // As LinuxCNC: a return leaves the subroutine it is in, whatever its label (its
                // demos write "o<test_return> return" inside "o<test_return> if").
                if (open_.empty() || open_line(0).kind != OKind::kSub) {
                    fail(o, oline_text(o) + " outside a subroutine");
                }
                break;
            case OKind::kCall:
                break;
            case OKind::kIf:
            case OKind::kDo:
            case OKind::kRepeat:
                open_.push_back(k);
                break;
            case OKind::kElseif:
            case OKind::kElse: {
                const std::size_t opener = close(k, o, OKind::kIf);
                line(opener).partner = ProgramStructure::kNone;
                auto& branches = s_.branches[opener];
                if (!branches.empty() && line(branches.back()).kind == OKind::kElse) {
                    fail(o, oline_text(o) + " after the else of its if");
                }
                branches.push_back(k);
                break;
            }
            case OKind::kEndif: {
                const std::size_t opener = close(k, o, OKind::kIf);
                open_.pop_back();
                if (const auto found = s_.branches.find(opener); found != s_.branches.end()) {
                    for (std::size_t branch : found->second) line(branch).partner = k;
                }
                break;
            }
            case OKind::kWhile:
                if (!open_.empty() && open_line(open_.size() - 1).kind == OKind::kDo &&
                    open_line(open_.size() - 1).label == o.label) {
                    close(k, o, OKind::kDo);
                    line(k).closes_do = true;
                } else {
                    open_.push_back(k);
                }
                break;
            case OKind::kEndwhile:
                close(k, o, OKind::kWhile);
                break;
            case OKind::kEndrepeat:
                close(k, o, OKind::kRepeat);
                break;
            case OKind::kBreak:
            case OKind::kContinue: {
                for (std::size_t i = open_.size(); i-- > 0;) {
                    const OLine& candidate = open_line(i);
                    if (candidate.kind == OKind::kSub) break;
                    if (is_loop(candidate.kind) && candidate.label == o.label) {
                        line(k).partner = open_[i];
                        return;
                    }
                }
                fail(o, oline_text(o) + " outside a loop of its label (while, do or repeat)");
            }
        }
    }

    const std::vector<std::string_view>& lines_;
    const std::string& file_;
    ProgramStructure s_;
    std::vector<std::size_t> open_;  ///< lines of the open sub/if/while/do/repeat statements
};

}  // namespace

const char* okind_name(OKind kind) {
    for (const auto& k : kKeywords) {
        if (k.kind == kind) return k.name;
    }
    return "?";
}

std::string oline_text(const OLine& o) {
    const bool numbered = !o.label.empty() && is_digit(o.label[0]);
    return "O" + (numbered ? o.label : "<" + o.label + ">") + " " + okind_name(o.kind);
}

std::optional<OLine> scan_oword(std::string_view text, std::size_t line_number,
                                const std::string& file) {
    LineCursor c{text, line_number, file, 0};
    c.skip_blanks();
    if (upper(c.peek()) == 'N') {
        const std::size_t save = c.i++;
        c.skip_blanks();
        while (is_digit(c.peek())) ++c.i;
        c.skip_blanks();
        if (upper(c.peek()) != 'O') c.i = save;
    }
    if (upper(c.peek()) != 'O') return std::nullopt;
    OLine o;
    o.at = c.at(c.i);
    const std::size_t o_index = c.i++;
    c.skip_blanks();
    if (c.peek() == '<') {
        const std::size_t close = text.find('>', c.i);
        if (close == std::string_view::npos) c.fail(c.i, "unclosed O-word name '<'");
        for (std::size_t k = c.i + 1; k < close; ++k) {
            const char ch = text[k];
            if (!is_blank(ch))
                o.label += ch >= 'A' && ch <= 'Z' ? static_cast<char>(ch - 'A' + 'a') : ch;
        }
        if (o.label.empty()) c.fail(c.i, "empty O-word name '<>'");
        c.i = close + 1;
    } else if (is_digit(c.peek())) {
        while (is_digit(c.peek())) o.label += c.text[c.i++];
        const std::size_t nonzero = o.label.find_first_not_of('0');
        o.label = nonzero == std::string::npos ? "0" : o.label.substr(nonzero);
    } else if (c.peek() == '#') {
        // LinuxCNC: a call's label may be a parameter's value ("o#<sub> call"); skip the
        // reference here, it is read when the call runs.
        o.label_value_at = c.i;
        o.label = "#";
        ++c.i;
        if (c.peek() == '<') {
            const std::size_t close = text.find('>', c.i);
            if (close == std::string_view::npos) c.fail(c.i, "unclosed parameter name '<'");
            c.i = close + 1;
        } else {
            while (is_digit(c.peek())) ++c.i;
        }
        if (c.i == o.label_value_at + 1) {
            c.fail(o.label_value_at, "an O-word label from a parameter is #<name> or #number");
        }
    } else {
        c.fail(o_index, "O-word without a number or <name>");
    }
    c.skip_blanks();
    const std::size_t keyword_at = c.i;
    std::string keyword;
    while (is_letter(c.peek())) keyword += static_cast<char>(upper(c.text[c.i++]) - 'A' + 'a');
    for (const auto& k : kKeywords) {
        if (keyword == k.name) {
            o.kind = k.kind;
            o.args_begin = c.i;
            if (o.label_value_at != 0 && o.kind != OKind::kCall) {
                c.fail(o_index, "only a call may take its label from a parameter (O#... call)");
            }
            return o;
        }
    }
    c.fail(keyword.empty() ? o_index : keyword_at,
           keyword.empty() ? "O-word without a keyword (sub, endsub, call, return, if, elseif, "
                             "else, endif, while, endwhile, do, repeat, endrepeat, break, "
                             "continue)"
                           : "unknown O-word keyword \"" + keyword + "\"");
}

ProgramStructure scan_structure(const std::vector<std::string_view>& lines,
                                const std::string& file) {
    return StructureScanner(lines, file).scan();
}

}  // namespace pathstream::host::gcode
