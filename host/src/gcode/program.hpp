// Runs a whole G-code program: the lines in the order O-words (calls, branches, loops) give,
// within budgets, each block lexed with the parameters of the moment, decoded and executed.
#pragma once

#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "interpreter.hpp"
#include "oword.hpp"
#include "parameters.hpp"

namespace pathstream::host::gcode {

/// Calls nested at most: LinuxCNC's INTERP_SUB_ROUTINE_LEVELS (10) counts the main program.
constexpr std::size_t kMaxCallDepth = 9;
/// Subroutine files loaded at most (each once, its characters counted in the budget).
constexpr std::size_t kMaxSubroutineFiles = 100;

/// Runs `lines` (the program's lines, without line breaks) through `interpreter`. Codes in
/// `ignored` are skipped; the first time each is met, a warning "file:line:col: ..." is
/// appended to `warnings` (also for grbl '$' lines). Throws InputError as the stages do and
/// for O-word errors (an unknown subroutine, a missing condition) and when `budget`'s blocks,
/// characters or loop passes are spent. A call of
/// a subroutine the program does not define loads NAME.ngc from the first directory of
/// `search_path` that has it (LinuxCNC's subroutine files); errors there name that file.
void run_program(const std::vector<std::string_view>& lines, const std::string& file,
                 const std::set<std::string>& ignored, Interpreter& interpreter,
                 Parameters& parameters, std::vector<std::string>& warnings,
                 const GcodeBudget& budget, const std::vector<std::string>& search_path = {});

}  // namespace pathstream::host::gcode
