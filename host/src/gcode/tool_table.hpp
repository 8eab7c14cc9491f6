// A tool table in LinuxCNC's format ("T1 P1 Z0.511 D3 ;comment" a line): what G43 H reads.
#pragma once

#include <map>
#include <string>

#include "axes.hpp"

namespace pathstream::host::gcode {

/// One tool's line: its offsets (machine units: mm, degrees) and diameter.
struct ToolEntry {
    long number = 0;      ///< T
    long pocket = 0;      ///< P (0 when absent)
    Axes offsets{};       ///< X Y Z A B C U V W (0 when absent)
    double diameter = 0;  ///< D
    std::string comment;  ///< after ';'
};

/// Tools by number. Empty: no table given (G43 H then fails naming the missing table).
class ToolTable {
public:
    /// Parses `text` (a whole table file, named `file` in errors). Words: T (required, whole,
    /// >= 0), P, X Y Z A B C U V W, D (>= 0), I J Q (accepted and ignored: lathe tool angles and
    /// orientation); ';' starts the comment. Throws InputError "file:line:col: ..." for an
    /// unknown letter, a malformed number, a line without T, a tool given twice.
    static ToolTable parse(const std::string& text, const std::string& file);
    /// Reads and parses a file. Throws InputError when it cannot be read.
    static ToolTable load(const std::string& file);

    /// The tool numbered `number`, or nullptr. O(log n).
    const ToolEntry* find(long number) const;
    bool empty() const { return tools_.empty(); }
    const std::string& source() const { return source_; }

private:
    std::map<long, ToolEntry> tools_;
    std::string source_;
};

}  // namespace pathstream::host::gcode
