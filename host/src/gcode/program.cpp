// Program flow: O-word calls, branches and loops, budgets, skipped codes
// (docs/formats-gcode.md, "O-words" and "Budgets").
#include "program.hpp"

#include <cctype>
#include <cmath>
#include <deque>
#include <fstream>
#include <map>
#include <sstream>

#include "cursor.hpp"
#include "expression.hpp"
#include "lexer.hpp"

namespace pathstream::host::gcode {

namespace {

class Runner {
public:
    Runner(const std::vector<std::string_view>& lines, const std::string& file,
           const std::set<std::string>& ignored, Interpreter& interpreter, Parameters& parameters,
           std::vector<std::string>& warnings, const GcodeBudget& budget,
           const std::vector<std::string>& search_path)
        : lines_(lines),
          budget_(budget),
          file_(file),
          search_path_(search_path),
          ignored_(ignored),
          interpreter_(interpreter),
          parameters_(parameters),
          warnings_(warnings),
          structure_(scan_structure(lines, file)) {
        interpreter_.set_warn([this](const std::string& code, SourceLocation at,
                                     const std::string& text) { warn(code, at, text); });
    }

    void run() {
        frames_.push_back(Frame{});
        std::size_t pc = 0;
        while (pc < lines_.size()) {
            characters_ += lines_[pc].size();
            if (++blocks_ > budget_.blocks || characters_ > budget_.characters) {
                throw InputError(file_of(pc), SourceLocation{line_of(pc), 1},
                                 "more than " + std::to_string(budget_.blocks) + " lines or " +
                                     std::to_string(budget_.characters) +
                                     " characters run (the reader's limit; a loop that never "
                                     "ends?)");
            }
            if (structure_.olines.count(pc) != 0) {
                pc = control(pc);
                continue;
            }
            const std::string& file = file_of(pc);
            const auto block = lex_line(lines_[pc], line_of(pc), file, parameters_);
            ++pc;
            if (!block) continue;
            if (block->dollar) {
                warn("$", block->start, "grbl '$' line skipped");
                continue;
            }
            const Command command = decode_block(*block, file, ignored_);
            for (const IgnoredCode& code : command.ignored) {
                warn(code.name, code.at, code.name + " skipped (it means nothing to this machine)");
            }
            // As LinuxCNC: the line's values were read with the old parameters; the settings
            // take effect before the block runs.
            for (const Assignment& a : block->assignments) parameters_.set(a.target, a.value);
            if (command.skip) continue;
            interpreter_.set_file(file);
            if (!interpreter_.execute(command)) return;
        }
    }

private:
    struct Unit {
        std::size_t begin = 0;  ///< its first line's index in lines_
        std::string file;
    };
    struct Frame {
        std::size_t return_to = 0;
        std::map<std::size_t, long> repeats_left;  ///< repeat line -> passes still to run
    };

    const OLine& o(std::size_t pc) const { return structure_.olines.at(pc); }

    [[noreturn]] void fail(const OLine& line, const std::string& message) const {
        throw InputError(line.file ? *line.file : file_, line.at, message);
    }

    // Lines past the program's own are subroutine files', appended as they are called.
    const Unit& unit_of(std::size_t pc) const {
        std::size_t k = units_.size();
        while (k > 0 && units_[k - 1].begin > pc) --k;
        return units_[k - 1];
    }
    const std::string& file_of(std::size_t pc) const {
        return pc < main_lines_ ? file_ : unit_of(pc).file;
    }
    std::size_t line_of(std::size_t pc) const {
        return pc < main_lines_ ? pc + 1 : pc - unit_of(pc).begin + 1;
    }

    // "O<name> call" of a subroutine the program does not define: LinuxCNC's subroutine files,
    // NAME.ngc holding "O<name> sub" ... "endsub", from the search path, loaded once.
    std::size_t external_sub(const OLine& line, const std::string& label) {
        if (const auto known = structure_.subs.find(label); known != structure_.subs.end())
            return known->second;
        const bool numbered = !label.empty() && std::isdigit(static_cast<unsigned char>(label[0]));
        const std::string what = "O" + (numbered ? label : "<" + label + ">") + " call";
        if (search_path_.empty()) fail(line, what + ": no such subroutine in this file");
        std::string found;
        for (const std::string& dir : search_path_) {
            const std::string candidate =
                (dir.empty() ? std::string(".") : dir) + "/" + label + ".ngc";
            if (std::ifstream(candidate).good()) {
                found = candidate;
                break;
            }
        }
        if (found.empty()) {
            std::string dirs;
            for (const std::string& dir : search_path_) dirs += (dirs.empty() ? "" : ", ") + dir;
            fail(line, what + ": no such subroutine in this file, nor " + label +
                           ".ngc in the subroutine path (" + dirs + ")");
        }
        if (units_.size() >= kMaxSubroutineFiles) {
            fail(line, what + ": more than " + std::to_string(kMaxSubroutineFiles) +
                           " subroutine files (the reader's limit)");
        }
        std::ifstream in(found, std::ios::binary);
        std::ostringstream buffer;
        buffer << in.rdbuf();
        texts_.push_back(buffer.str());
        characters_ += texts_.back().size();
        const std::size_t begin = lines_.size();
        units_.push_back(Unit{begin, found});
        std::vector<std::string_view> added;
        std::string_view rest(texts_.back());
        while (!rest.empty()) {
            const std::size_t end = rest.find('\n');
            std::string_view current = rest.substr(0, end);
            rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
            if (!current.empty() && current.back() == '\r') current.remove_suffix(1);
            added.push_back(current);
        }
        ProgramStructure s = scan_structure(added, units_.back().file);
        const auto sub = s.subs.find(label);
        if (sub == s.subs.end()) {
            fail(line, what + ": " + found + " does not define O<" + label + "> sub");
        }
        for (auto& [index, o] : s.olines) {
            o.file = &units_.back().file;
            if (o.partner != ProgramStructure::kNone) o.partner += begin;
            structure_.olines.emplace(index + begin, o);
        }
        for (auto& [index, branches] : s.branches) {
            for (std::size_t& b : branches) b += begin;
            structure_.branches.emplace(index + begin, branches);
        }
        for (const auto& [name, index] : s.subs) structure_.subs.emplace(name, index + begin);
        lines_.insert(lines_.end(), added.begin(), added.end());
        return sub->second + begin;
    }

    void warn(const std::string& code, SourceLocation at, const std::string& what) {
        if (!warned_.insert(code).second) return;
        warnings_.push_back(file_ + ":" + std::to_string(at.line) + ":" +
                            std::to_string(at.column) + ": " + what +
                            "; later ones are skipped without a warning");
    }

    // The [ ] values after an O-word's keyword, at most `most`.
    std::vector<double> arguments(std::size_t pc, std::size_t most) {
        LineCursor c{lines_[pc], line_of(pc), file_of(pc), o(pc).args_begin};
        std::vector<double> values;
        while (true) {
            c.skip_blanks();
            if (c.peek() == '(') {
                const auto close = c.text.find(')', c.i);
                if (close == std::string_view::npos) c.fail(c.i, "unclosed comment '('");
                c.i = close + 1;
                continue;
            }
            if (c.done() || c.peek() == ';') break;
            if (c.peek() != '[' || values.size() == most) {
                c.fail(c.i, "unexpected " + describe_char(c.peek()) + " after " +
                                oline_text(o(pc)) + (most ? " (values are written in [ ])" : ""));
            }
            values.push_back(read_value(c, parameters_, 0));
        }
        return values;
    }

    double condition(std::size_t pc) {
        const std::vector<double> v = arguments(pc, 1);
        if (v.empty()) fail(o(pc), oline_text(o(pc)) + " needs a value in [ ]");
        return v[0];
    }

    void loop_pass(std::size_t loop_line) {
        if (++loop_passes_ > budget_.loop_passes) {
            fail(o(loop_line), oline_text(o(loop_line)) + ": more than " +
                                   std::to_string(budget_.loop_passes) +
                                   " loop passes in all (the reader's limit; a loop that never "
                                   "ends?)");
        }
    }

    // Runs the O-word on line pc; returns the next line to run.
    std::size_t control(std::size_t pc) {
        const OLine& line = o(pc);
        const std::size_t partner = line.partner;
        switch (line.kind) {
            case OKind::kSub:
                return partner + 1;  // a definition: skipped until called
            case OKind::kEndsub:
            case OKind::kReturn: {
                const std::vector<double> v = arguments(pc, 1);
                if (frames_.size() == 1) fail(line, oline_text(line) + " outside a call");
                if (!v.empty()) parameters_.set(ParameterRef{0, "_value"}, v[0]);
                parameters_.set(ParameterRef{0, "_value_returned"}, v.empty() ? 0 : 1);
                const std::size_t back = frames_.back().return_to;
                frames_.pop_back();
                parameters_.leave_call();
                interpreter_.leave_call();
                return back;
            }
            case OKind::kCall: {
                std::string label = line.label;
                if (line.label_value_at != 0) {
                    LineCursor c{lines_[pc], line_of(pc), file_of(pc), line.label_value_at};
                    const double v = read_value(c, parameters_, 0);
                    if (v != std::floor(v) || v < 0 || v > 1e9) {
                        fail(line, "O# call: the label's value " + std::to_string(v) +
                                       " is not a whole number >= 0");
                    }
                    label = std::to_string(static_cast<long>(v));
                }
                const std::size_t sub_line = external_sub(line, label);
                const std::vector<double> args = arguments(pc, Parameters::kCallArguments);
                if (frames_.size() > kMaxCallDepth) {
                    fail(line, oline_text(line) + ": calls nested more than " +
                                   std::to_string(kMaxCallDepth) + " deep");
                }
                parameters_.enter_call(args);
                interpreter_.enter_call();
                frames_.push_back(Frame{pc + 1, {}});
                return sub_line + 1;
            }
            case OKind::kIf:
                if (condition(pc) != 0) return pc + 1;
                return next_branch(pc);
            case OKind::kElseif:
            case OKind::kElse:
                return partner + 1;  // the branch before ran: leave the if
            case OKind::kEndif:
            case OKind::kDo:
                arguments(pc, 0);
                return pc + 1;
            case OKind::kWhile:
                if (line.closes_do) {
                    if (condition(pc) == 0) return pc + 1;
                    loop_pass(partner);
                    return partner + 1;
                }
                return condition(pc) != 0 ? pc + 1 : partner + 1;
            case OKind::kEndwhile:
                arguments(pc, 0);
                loop_pass(partner);
                return partner;
            case OKind::kRepeat: {
                // As LinuxCNC: the count is rounded to the nearest whole number.
                const double n = std::nearbyint(condition(pc));
                if (n < 1) return partner + 1;
                frames_.back().repeats_left[pc] = n > static_cast<double>(budget_.loop_passes)
                                                      ? static_cast<long>(budget_.loop_passes) + 1
                                                      : static_cast<long>(n) - 1;
                return pc + 1;
            }
            case OKind::kEndrepeat: {
                arguments(pc, 0);
                long& left = frames_.back().repeats_left[partner];
                if (left <= 0) return pc + 1;
                --left;
                loop_pass(partner);
                return partner + 1;
            }
            case OKind::kBreak:
                arguments(pc, 0);
                return o(partner).partner + 1;
            case OKind::kContinue: {
                arguments(pc, 0);
                // While: test again; do: its closing while tests; repeat: endrepeat counts.
                return o(partner).kind == OKind::kWhile ? partner : o(partner).partner;
            }
        }
        return pc + 1;
    }

    // After a false if (or elseif): the first branch whose condition holds, else the endif.
    std::size_t next_branch(std::size_t if_line) {
        const auto found = structure_.branches.find(if_line);
        if (found != structure_.branches.end()) {
            for (std::size_t branch : found->second) {
                if (o(branch).kind == OKind::kElse) {
                    arguments(branch, 0);
                    return branch + 1;
                }
                if (condition(branch) != 0) return branch + 1;
            }
        }
        return o(if_line).partner + 1;
    }

    std::vector<std::string_view> lines_;
    GcodeBudget budget_;
    const std::string& file_;
    const std::vector<std::string>& search_path_;
    std::size_t main_lines_ = lines_.size();
    std::deque<Unit> units_;         ///< subroutine files (stable: messages refer to names)
    std::deque<std::string> texts_;  ///< their text
    const std::set<std::string>& ignored_;
    Interpreter& interpreter_;
    Parameters& parameters_;
    std::vector<std::string>& warnings_;
    ProgramStructure structure_;
    std::vector<Frame> frames_;
    std::set<std::string> warned_;
    std::size_t blocks_ = 0;
    std::size_t characters_ = 0;
    std::size_t loop_passes_ = 0;
};

}  // namespace

void run_program(const std::vector<std::string_view>& lines, const std::string& file,
                 const std::set<std::string>& ignored, Interpreter& interpreter,
                 Parameters& parameters, std::vector<std::string>& warnings,
                 const GcodeBudget& budget, const std::vector<std::string>& search_path) {
    Runner(lines, file, ignored, interpreter, parameters, warnings, budget, search_path).run();
}

}  // namespace pathstream::host::gcode
