// O-words (LinuxCNC's subroutines and control flow): finding them on a line without running
// anything, and matching each opening O-word with its partners across the program.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "pathstream/host/path.hpp"

namespace pathstream::host::gcode {

enum class OKind {
    kSub,
    kEndsub,
    kCall,
    kReturn,
    kIf,
    kElseif,
    kElse,
    kEndif,
    kWhile,
    kEndwhile,
    kDo,
    kRepeat,
    kEndrepeat,
    kBreak,
    kContinue,
};

/// "sub", "endwhile": the keyword as written in programs.
const char* okind_name(OKind kind);

/// One O-word statement.
struct OLine {
    std::string label;  ///< "100" (leading zeros dropped) or "name" (lower case, no blanks)
    OKind kind = OKind::kSub;
    SourceLocation at;           ///< where the O is
    std::size_t args_begin = 0;  ///< index in the line just after the keyword
    /// sub <-> endsub, if/elseif/else -> endif, while <-> endwhile, do <-> its closing while,
    /// repeat <-> endrepeat, break/continue -> the loop's first line (0-based line index).
    std::size_t partner = static_cast<std::size_t>(-1);
    bool closes_do = false;  ///< a while that ends a do
    /// `O#<sub> call`: the label is the value at this index of the line (a whole number),
    /// read when the call runs; 0: a written label.
    std::size_t label_value_at = 0;
    /// The file the line is in when it is not the program's (a subroutine file); nullptr: the
    /// program's.
    const std::string* file = nullptr;
};

/// "O100 while", "O<name> sub": how messages name a statement.
std::string oline_text(const OLine& o);

/// The O-word statement on a line, if the line holds one (after an optional N word).
/// Throws InputError for an O without a label or with an unknown keyword.
std::optional<OLine> scan_oword(std::string_view text, std::size_t line_number,
                                const std::string& file);

/// Every O-word of a program and how they pair up. Indices are 0-based line indices.
struct ProgramStructure {
    static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
    /// Line index -> its O-word; only lines that hold one (memory follows the O-words).
    std::unordered_map<std::size_t, OLine> olines;
    std::map<std::size_t, std::vector<std::size_t>> branches;  ///< if -> its elseif/else lines
    std::map<std::string, std::size_t> subs;                   ///< label -> sub line
};

/// Scans all lines. Throws InputError at the offending O-word for unmatched or misnested
/// statements, a sub defined twice or inside another block, break/continue outside a loop of
/// their label and return outside its sub.
ProgramStructure scan_structure(const std::vector<std::string_view>& lines,
                                const std::string& file);

}  // namespace pathstream::host::gcode
