// The G-code reader's first stage: one line of text -> the words of one block, with where
// each word starts, values evaluated against the current parameters. Knows the syntax
// (comments, numbers, expressions, parameter settings), not what codes mean.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "parameters.hpp"
#include "pathstream/host/path.hpp"

namespace pathstream::host::gcode {

/// One word: an upper-case letter and its number.
struct Word {
    char letter = 0;    ///< 'A'..'Z', upper case; '@', '^' (polar distance and angle)
    double value = 0;   ///< the value (file units), finite
    std::string text;   ///< the value exactly as written, for messages ("01", "[#1+2]")
    SourceLocation at;  ///< where the letter is
};

/// A parameter setting "#1=..." on the line; LinuxCNC applies them after reading the line.
struct Assignment {
    ParameterRef target;
    double value = 0;
    SourceLocation at;  ///< where the '#' is
};

/// The words of one line (a block), line number word N removed.
struct Block {
    std::vector<Word> words;
    std::vector<Assignment> assignments;
    SourceLocation start;  ///< the first word of the block (the N word if there is one)
    bool dollar = false;   ///< a grbl '$' line ("$H", "$X"): nothing else was read
};

/// Reads line `line_number` (1-based; `text` without its line break), evaluating values with
/// `parameters` as they are before the line. Returns nullopt for a line with nothing in it
/// (blank, comments only, or a '%' line). Throws InputError naming `file` and the column for:
/// block delete '/', an unclosed '(' comment, an O-word, a checksum '*nn' that does not match
/// the XOR of the bytes before it, any other character outside a comment that starts no word, an N
/// word that is not first, a letter without a value, a malformed number (sign, digits, at most one
/// '.', no exponent), bad expressions and parameter references (see read_value).
std::optional<Block> lex_line(std::string_view text, std::size_t line_number,
                              const std::string& file, const Parameters& parameters);

}  // namespace pathstream::host::gcode
