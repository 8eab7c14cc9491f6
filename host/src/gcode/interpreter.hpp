// The G-code reader's third stage: executes decoded blocks against the modal state (units,
// distance modes, motion mode, feed, pen) and turns moves into pen-down Bezier pieces.
#pragma once

#include <optional>
#include <string>

#include "command.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/path.hpp"
#include "runs.hpp"
#include "vec2.hpp"

namespace pathstream::host::gcode {

class Interpreter {
public:
    /// `options` must already be checked; `file` names the source in error messages.
    Interpreter(const std::string& file, const GcodeOptions& options);

    /// Executes one block (in LinuxCNC's order: units, distance modes, F, spindle, dwell,
    /// motion, program end). Returns false after M2 or M30: read no further.
    /// Throws InputError at the offending word.
    bool execute(const Command& c);

    /// The path drawn. Throws InputError ("file: no pen-down moves ...") if it is empty.
    Path finish();

private:
    [[noreturn]] void fail(SourceLocation at, const std::string& message) const;

    double scale() const { return inch_ ? 25.4 : 1.0; }
    /// A length word in mm, checked against the coordinate range.
    double length(const Word& w) const;
    /// Checks that a computed position or control point is within the coordinate range.
    void check_point(Vec2 p, SourceLocation at) const;
    /// Whether a move from Z `from` to Z `to` draws.
    bool pen_down(double from, double to) const;

    void check_words_used(const Command& c, Motion move, bool moving) const;
    void move(const Command& c, Motion move, SourceLocation at);
    void line(Vec2 to, double z_to, SourceLocation at);
    void arc(const Command& c, Motion move, Vec2 to, SourceLocation at);
    void cubic(const Command& c, Vec2 to, SourceLocation at);
    void quadratic(const Command& c, Vec2 to, SourceLocation at);
    /// Draws (pen down) or travels along pieces ending at `to`, then moves there.
    void follow(const std::vector<Cubic>& pieces, bool down, Vec2 to, SourceLocation at);

    const std::string& file_;
    GcodeOptions options_;
    RunBuilder runs_;

    Vec2 position_;         ///< mm; X0 Y0 at the start
    double z_ = 0;          ///< mm
    bool z_known_ = false;  ///< false until a Z word: the pen counts as up (kZ)
    Motion motion_ = Motion::kNone;
    bool inch_ = false;                       ///< G20
    bool incremental_ = false;                ///< G91
    bool arc_incremental_ = true;             ///< G91.1 (LinuxCNC's default)
    double feed_ = 0;                         ///< mm/s; 0 until F
    bool spindle_ = false;                    ///< M3/M4 given, no M5 since
    std::optional<Vec2> last_cubic_control_;  ///< second control point of the last move, if G5
};

}  // namespace pathstream::host::gcode
