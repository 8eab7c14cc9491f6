// The G-code reader's second stage: the words of one block -> what the block asks for (its
// G and M codes sorted by modal group, and its value words). Rejects codes the reader does
// not support and blocks that give two codes of one group or one letter twice.
#pragma once

#include <array>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "axes.hpp"
#include "lexer.hpp"
#include "pathstream/host/path.hpp"

namespace pathstream::host::gcode {

/// Motion modes (modal group 1). kNone: no motion mode yet, or G80.
enum class Motion {
    kNone,
    kRapid,
    kLine,
    kArcCw,
    kArcCcw,
    kCubic,
    kQuadratic,
    kNurbs,
    kPeckChipBreak,    ///< G73
    kDrill,            ///< G81
    kDrillDwell,       ///< G82
    kPeck,             ///< G83
    kBore,             ///< G85: feed in, feed out
    kBoreSpindleStop,  ///< G86: feed in, spindle stop, rapid out
    kBoreDwell,        ///< G89: feed in, dwell, feed out
};

/// Whether `m` is a canned cycle (G73, G81-G89).
inline bool is_cycle(Motion m) {
    return m >= Motion::kPeckChipBreak;
}

/// Cutter radius compensation (group 7): G40 off; G41/G42 left/right with D the tool table's
/// tool; G41.1/G42.1 with D the diameter.
enum class CutterComp { kOff, kLeft, kRight, kLeftDiameter, kRightDiameter };

/// G43 (H from the tool table), G43.1 (dynamic, from the block's axis words), G49 (none).
enum class ToolLength { kTable, kDynamic, kCancel };

/// The non-modal codes of group 0 (one per block).
enum class NonModal {
    kNone,
    kDwell,           ///< G4
    kSetOffset,       ///< G92
    kClearOffset,     ///< G92.1
    kSuspendOffset,   ///< G92.2
    kRestoreOffset,   ///< G92.3
    kHome,            ///< G28
    kSetHome,         ///< G28.1
    kHome2,           ///< G30
    kSetHome2,        ///< G30.1
    kMachineCoords,   ///< G53
    kSetCoordinates,  ///< G10 (L2, L20)
};

/// A code the reader skips (it has no meaning for the machine), where it first appeared.
struct IgnoredCode {
    std::string name;  ///< "M6", "G43"
    SourceLocation at;
};

/// One block, decoded. S and T leave no trace here.
struct Command {
    SourceLocation start;                          ///< the block's first word
    std::optional<Motion> motion;                  ///< G0 G1 G2 G3 G5 G5.1 G80
    SourceLocation motion_at;                      ///< where that G word is
    std::optional<bool> inch;                      ///< G20 (true) / G21 (false)
    std::optional<bool> incremental;               ///< G91 (true) / G90 (false)
    std::optional<bool> arc_incremental;           ///< G91.1 (true) / G90.1 (false)
    std::optional<Plane> plane;                    ///< G17, G18, G19
    std::optional<bool> inverse_time;              ///< G93 (true) / G94 (false)
    std::optional<bool> retract_to_r;              ///< G99 (true) / G98 (false)
    std::optional<std::size_t> coordinate_system;  ///< G54 (0) .. G59.3 (8)
    SourceLocation coordinate_system_at;
    std::optional<ToolLength> tool_length;  ///< G43, G43.1, G49
    SourceLocation tool_length_at;
    std::optional<CutterComp> cutter_comp;  ///< G40, G41, G42, G41.1, G42.1
    SourceLocation cutter_comp_at;
    NonModal non_modal = NonModal::kNone;    ///< G4, G28, G30, G53, G92...
    SourceLocation non_modal_at;             ///< where that G word is
    bool nurbs_end = false;                  ///< G5.3
    std::optional<CornerMode> path_control;  ///< G61 (exact path), G61.1 (exact stop), G64 (P, Q)
    SourceLocation path_control_at;          ///< where that G word is
    std::optional<bool> spindle_on;          ///< M3, M4 (true) / M5 (false)
    bool spindle_reverse = false;            ///< M4
    SourceLocation spindle_at;               ///< where that M word is
    /// M7 (mist), M8 (flood): on; M9: both off. M7 and M8 may share a block, as in LinuxCNC.
    bool mist = false, flood = false, coolant_off = false;
    bool end_program = false;    ///< M2, M30
    bool pause = false;          ///< M0, M1
    SourceLocation pause_at;     ///< where the M0, M1 or M6 is
    bool optional_stop = false;  ///< M1
    bool pallet_change = false;  ///< M60
    bool tool_change = false;    ///< M6 (when not skipped)
    bool set_tool = false;       ///< M61 Q: the tool in the spindle, no change
    /// M70 save, M71 invalidate, M72 restore, M73 save until the subroutine returns; 0: none.
    int modal_state = 0;
    SourceLocation modal_state_at;
    bool spindle_speed_mode = false;  ///< G96, G97 (no effect: S drives no output)
    /// Codes skipped in this block; when `skip` the whole block is skipped (it held only
    /// skipped codes and their words).
    std::vector<IgnoredCode> ignored;
    bool skip = false;
    /// The value words (A-Z but G M N O), indexed by letter - 'A'.
    std::array<std::optional<Word>, 26> values;
    /// Polar coordinates: '@' the distance, '^' the angle in degrees (LinuxCNC).
    std::optional<Word> polar_distance, polar_angle;

    /// The value word for `letter` ('A'..'Z'), or nullptr.
    const Word* value(char letter) const {
        const auto& w = values[static_cast<std::size_t>(letter - 'A')];
        return w ? &*w : nullptr;
    }
};

/// Codes skipped when no --ignore-code is given: M6 (tool change; not on a machine), M7 M8 M9
/// (coolant), M48-M53 (LinuxCNC's override and adaptive feed switches),
/// M17 M18 M84 (stepper power), M106 M107 (fan), M117 (display text), M300 (beep),
/// M888 M2000 (DexArm modes).
const std::set<std::string>& default_ignored_codes();

/// "M6", "G43", "G92.1": a code as the user names it, normalised (upper case, no leading
/// zeros); nullopt when `text` is no G or M code.
std::optional<std::string> normalise_code_name(const std::string& text);

/// Decodes a block. Codes named in `ignored` are listed in Command::ignored and skipped; a
/// block of only such codes and non-axis words is skipped whole. Throws InputError at the
/// offending word for: an unsupported letter, G or M code, two codes of one modal group, and a
/// letter given twice.
Command decode_block(const Block& block, const std::string& file,
                     const std::set<std::string>& ignored);

/// "G1", "G90.1": the name of a G code given in tenths (10, 901).
std::string g_code_name(long tenths);

}  // namespace pathstream::host::gcode
