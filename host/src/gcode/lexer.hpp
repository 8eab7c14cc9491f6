// The G-code reader's first stage: one line of text -> the words of one block, with where
// each word starts. Knows the syntax (comments, numbers, letters), not what codes mean.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pathstream/host/path.hpp"

namespace pathstream::host::gcode {

/// One word: an upper-case letter and its number.
struct Word {
    char letter = 0;    ///< 'A'..'Z', upper case
    double value = 0;   ///< the number as written (file units), finite
    std::string text;   ///< the number exactly as written, for messages ("01", "90.1")
    SourceLocation at;  ///< where the letter is
};

/// The words of one line (a block), line number word N removed.
struct Block {
    std::vector<Word> words;
    SourceLocation start;  ///< the first word of the block (the N word if there is one)
};

/// Reads line `line_number` (1-based; `text` without its line break). Returns nullopt for a
/// line with no words (blank, comments only, or a '%' line). Throws InputError naming `file`
/// and the column for: block delete '/', an unclosed '(' comment, '#' parameters and '['
/// expressions, O-words, a letter the reader does not support, any other character outside a
/// comment, an N word that is not first, a letter without a number, a malformed number
/// (sign, digits, at most one '.', no exponent) and a number too large for a double.
std::optional<Block> lex_line(std::string_view text, std::size_t line_number,
                              const std::string& file);

}  // namespace pathstream::host::gcode
