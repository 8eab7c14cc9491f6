// RS274NGC values as LinuxCNC reads them: numbers, [ ] expressions with binary operators,
// unary functions and parameter references (docs/formats-gcode.md, "Expressions").
#pragma once

#include "cursor.hpp"
#include "parameters.hpp"

namespace pathstream::host::gcode {

/// Reads one value at the cursor: a number ("-1.5", ".5"), "[expression]", "#parameter",
/// a function ("SIN[30]", "ATAN[1]/[2]", "EXISTS[#<name>]") or any of them after a unary
/// '-' or '+'. `letter` names the word in messages (0 inside an O-word); errors in a plain
/// number (not in brackets) are reported at `word_at`, the word's letter, when given. Leaves
/// the cursor after the value. Throws InputError at the offending character for bad syntax,
/// undefined named parameters, math errors (division by zero, SQRT of a negative, ...) and results
/// that are not finite.
double read_value(LineCursor& cursor, const Parameters& parameters, char letter,
                  std::size_t word_at = static_cast<std::size_t>(-1));

/// Reads the parameter reference after a '#' (the cursor is on the '#'): "#12", "#<name>",
/// "#[1+2]", "##1". Throws InputError for a number that is not whole or not in 1..5602.
ParameterRef read_parameter_ref(LineCursor& cursor, const Parameters& parameters);

}  // namespace pathstream::host::gcode
