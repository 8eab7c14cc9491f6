// The G-code reader's second stage: the words of one block -> what the block asks for (its
// G and M codes sorted by modal group, and its value words). Rejects codes the reader does
// not support and blocks that give two codes of one group or one letter twice.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "lexer.hpp"
#include "pathstream/host/path.hpp"

namespace pathstream::host::gcode {

/// Motion modes (modal group 1). kNone: no motion mode yet, or G80.
enum class Motion { kNone, kRapid, kLine, kArcCw, kArcCcw, kCubic, kQuadratic };

/// One block, decoded. Codes the reader accepts and ignores (G17, G40, G49, G54, G61, G61.1,
/// G64, G94, S, T) leave no trace here apart from `path_control` (G64 may carry P and Q).
struct Command {
    SourceLocation start;                 ///< the block's first word
    std::optional<Motion> motion;         ///< G0 G1 G2 G3 G5 G5.1 G80
    SourceLocation motion_at;             ///< where that G word is
    std::optional<bool> inch;             ///< G20 (true) / G21 (false)
    std::optional<bool> incremental;      ///< G91 (true) / G90 (false)
    std::optional<bool> arc_incremental;  ///< G91.1 (true) / G90.1 (false)
    bool dwell = false;                   ///< G4 (takes P)
    SourceLocation dwell_at;              ///< where the G4 word is
    bool path_control = false;            ///< G64 (may take P and Q)
    std::optional<bool> spindle_on;       ///< M3, M4 (true) / M5 (false)
    bool end_program = false;             ///< M2, M30
    /// The value words (F I J P Q R S T X Y Z), indexed by letter - 'A'.
    std::array<std::optional<Word>, 26> values;

    /// The value word for `letter` ('A'..'Z'), or nullptr.
    const Word* value(char letter) const {
        const auto& w = values[static_cast<std::size_t>(letter - 'A')];
        return w ? &*w : nullptr;
    }
};

/// Decodes a block. Throws InputError at the offending word for: an unsupported G or M code
/// (G18/G19: "only the XY plane (G17) is supported"), two codes of one modal group, and a
/// value letter given twice.
Command decode_block(const Block& block, const std::string& file);

/// "G1", "G90.1": the name of a G code given in tenths (10, 901).
std::string g_code_name(long tenths);

}  // namespace pathstream::host::gcode
