// The G-code reader's third stage: executes decoded blocks against the modal state (units,
// distance modes, offsets, motion mode, feed, pen) and turns moves into pen-down Bezier pieces.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "command.hpp"
#include "parameters.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/path.hpp"
#include "runs.hpp"
#include "vec2.hpp"

namespace pathstream::host::gcode {

/// What a program did with Z and the spindle, for choosing a pen mode (--gcode-pen auto).
struct PenEvidence {
    bool z_low = false;    ///< a Z word at or below z_down_max
    bool z_high = false;   ///< a Z word above z_down_max
    bool spindle = false;  ///< M3 or M4
};

class Interpreter {
public:
    /// `options` must already be checked (pen not kAuto); `file` names the source in error
    /// messages; `parameters` holds the G28/G30 positions and receives G92 offsets.
    Interpreter(const std::string& file, const GcodeOptions& options, Parameters& parameters);

    /// Executes one block (in LinuxCNC's order: units, distance modes, F, spindle, dwell,
    /// offsets and homing, motion, then M0/M1 and program end). Returns false after M2 or
    /// M30: read no further. Throws InputError at the offending word.
    bool execute(const Command& c);

    /// The path drawn. Throws InputError ("file: no pen-down moves ...") if it is empty,
    /// unless `allow_empty`.
    Path finish(bool allow_empty = false);

    const PenEvidence& evidence() const { return evidence_; }

private:
    [[noreturn]] void fail(SourceLocation at, const std::string& message) const;

    double scale() const { return inch_ ? 25.4 : 1.0; }
    /// A length word in mm, checked against the coordinate range.
    double length(const Word& w) const;
    /// Checks that a computed position or control point is within the coordinate range.
    void check_point(Vec2 p, SourceLocation at) const;
    /// Whether a feed move from Z `from` to Z `to` draws.
    bool pen_down(double from, double to) const;
    /// Whether the pen is down where the machine stands now (for G4).
    bool pen_down_now() const;

    /// G61, G61.1, G64 [P] [Q]: the corner rule for the moves that follow.
    void path_control(const Command& c);
    void check_words_used(const Command& c, Motion move, bool moving) const;
    /// G92, G92.1, G92.2, G92.3, G28.1, G30.1; G28 and G30 travel.
    void non_modal(const Command& c);
    /// Travel to `to` (mm, machine coordinates) with Z `z_to`.
    void travel(Vec2 to, double z_to);
    /// The block's X Y Z as machine coordinates in mm (G90/G91, G92 offset, G53).
    void targets(const Command& c, Vec2& to, double& z_to, bool machine) const;
    void move(const Command& c, Motion move, SourceLocation at);
    void line(Vec2 to, double z_to, SourceLocation at);
    void arc(const Command& c, Motion move, Vec2 to, SourceLocation at);
    /// Throws at `at` when an I J arc's end radius is too far from its start radius.
    void check_end_radius(double r0_mm, double r1_mm, SourceLocation at) const;
    void cubic(const Command& c, Vec2 to, SourceLocation at);
    void quadratic(const Command& c, Vec2 to, SourceLocation at);
    /// G5.2 blocks: collects a control point; G5.3 (or leaving G5.2) draws the curve.
    void nurbs_point(const Command& c, Vec2 to, SourceLocation at);
    void nurbs_end(SourceLocation at);
    /// Draws (pen down) or travels along pieces ending at `to`, then moves there.
    void follow(const std::vector<Cubic>& pieces, bool down, Vec2 to, SourceLocation at);

    const std::string& file_;
    GcodeOptions options_;
    Parameters& parameters_;
    RunBuilder runs_;
    PenEvidence evidence_;

    Vec2 position_;         ///< mm, machine coordinates; X0 Y0 at the start
    double z_ = 0;          ///< mm
    bool z_known_ = false;  ///< false until a Z word: the pen counts as up (kZ)
    Vec2 offset_;           ///< G92 offset (mm): machine = program + offset
    double z_offset_ = 0;   ///< G92 offset of Z (mm)
    Motion motion_ = Motion::kNone;
    bool inch_ = false;                       ///< G20
    bool incremental_ = false;                ///< G91
    bool arc_incremental_ = true;             ///< G91.1 (LinuxCNC's default)
    double feed_ = 0;                         ///< mm/s; 0 until F
    bool spindle_ = false;                    ///< M3/M4 given, no M5 since
    bool last_move_drew_ = false;             ///< kMotion: the pen is down
    std::optional<Vec2> last_cubic_control_;  ///< second control point of the last move, if G5

    struct NurbsPoint {
        Vec2 at;
        double weight = 1;
    };
    std::vector<NurbsPoint> nurbs_;  ///< G5.2 control points so far (the first: the start)
    int nurbs_order_ = 0;            ///< G5.2 L
    SourceLocation nurbs_at_;        ///< where the G5.2 is
};

}  // namespace pathstream::host::gcode
