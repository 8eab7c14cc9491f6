// The G-code reader's third stage: executes decoded blocks against the modal state (units,
// distance modes, plane, offsets, motion mode, feed, pen) and turns moves into pieces: pen-down
// runs, and on a machine whose moves keep their order (PenControl::kMachine) travel runs too.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "arc.hpp"
#include "axes.hpp"
#include "command.hpp"
#include "cutter_comp.hpp"
#include "parameters.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/path.hpp"
#include "runs.hpp"
#include "tool_table.hpp"

namespace pathstream::host::gcode {

/// What a program did with Z and the spindle, for choosing a pen mode (--gcode-pen auto).
struct PenEvidence {
    bool z_low = false;    ///< a Z word at or below z_down_max
    bool z_high = false;   ///< a Z word above z_down_max
    bool spindle = false;  ///< M3 or M4
};

class Interpreter {
public:
    /// `options` must already be checked (pen not kAuto, axes valid); `file` names the source
    /// in error messages; `parameters` holds the G28/G30 positions, the coordinate systems and
    /// receives G92 offsets; `tools` the tool table (G43 H).
    Interpreter(const std::string& file, const GcodeOptions& options, Parameters& parameters,
                const ToolTable& tools);

    /// The file the next blocks come from (a subroutine file's), for messages. The string must
    /// outlive the interpreter's use of it.
    void set_file(const std::string& file) { file_ = &file; }
    /// Where warnings go: (code, where, text); the runner says each code's first one.
    using Warn = std::function<void(const std::string&, SourceLocation, const std::string&)>;
    void set_warn(Warn warn) { warn_ = std::move(warn); }

    /// The program runner's calls: M73 restores the state it saved when its call returns.
    void enter_call() { ++call_depth_; }
    void leave_call();

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
    /// An axis word's value in machine units: mm (linear, G20 scaled) or degrees (rotary).
    double axis_value(const Word& w, std::size_t axis) const;
    /// Checks that a computed position or control point is within the coordinate range.
    void check_point(const Axes& p, SourceLocation at) const;
    /// Whether a feed move from Z `from` to Z `to` draws.
    bool pen_down(double from, double to) const;
    /// Whether the pen is down where the machine stands now (for G4).
    bool pen_down_now() const;
    bool machine() const { return options_.pen == PenControl::kMachine; }
    /// Whether the path has axis `axis` (else: Z is the pen signal; others are refused).
    bool on_path(std::size_t axis) const { return path_axis_[axis]; }

    void feed_word(const Command& c);
    /// "tool change to T2 (3 mm drill), line 6", "program stop (M0), line 9".
    std::string pause_note(const Command& c) const;
    /// G61, G61.1, G64 [P] [Q]: the corner rule for the moves that follow.
    void path_control(const Command& c);
    void check_words_used(const Command& c, Motion move, bool moving) const;
    /// G92, G92.1, G92.2, G92.3, G28.1, G30.1, G10; G28 and G30 travel.
    void non_modal(const Command& c);
    /// G10 L2, L20: a coordinate system's origin.
    void set_coordinates(const Command& c);
    /// M6: the selected tool is in the spindle (#5400, #5401-#5409, #5410 describe it).
    void load_tool();
    /// G54..G59.3 and G43/G43.1/G49: the offsets from program to machine coordinates.
    void offsets_modes(const Command& c);
    /// Program coordinates -> machine coordinates of one axis (G54.., G92, tool length).
    double offset(std::size_t axis) const;
    /// Travel to `to` (machine coordinates).
    void travel(const Axes& to, SourceLocation at);
    /// The block's axis words as machine coordinates (G90/G91, offsets, G53, polar @ ^).
    Axes targets(const Command& c, bool machine_coordinates) const;
    void move(const Command& c, Motion move, SourceLocation at);
    void line(const Axes& to, SourceLocation at);
    void arc(const Command& c, Motion move, const Axes& to, SourceLocation at);
    /// Throws at `at` when an I J arc's end radius is too far from its start radius.
    void check_end_radius(double r0_mm, double r1_mm, SourceLocation at) const;
    void cubic(const Command& c, const Axes& to, SourceLocation at);
    void quadratic(const Command& c, const Axes& to, SourceLocation at);
    /// G5.2 blocks: collects a control point; G5.3 (or leaving G5.2) draws the curve.
    void nurbs_point(const Command& c, const Axes& to, SourceLocation at);
    void nurbs_end(SourceLocation at);
    /// G73, G81-G89: one canned cycle block (L repeats).
    void canned_cycle(const Command& c, Motion cycle, SourceLocation at);
    /// The feed (mm/s along the path's axes) of a feed move made of `pieces`, from F, G93/G94
    /// and LinuxCNC's rule that F is along X Y Z when they move. Throws at `at` without F.
    double move_feed(const std::vector<Piece>& pieces, SourceLocation at) const;
    /// Plane pieces of a move from pos_ to `to` lifted into all axes: the plane's axes from
    /// the pieces, every other axis linear in the piece index (the arcs' equal angle steps).
    std::vector<Piece> lift(const std::vector<Cubic>& pieces, const Axes& to) const;
    /// Draws (pen down) or travels along pieces ending at `to`, then moves there. `feed`: the
    /// feed when it was fixed before (compensated moves), else from move_feed.
    void follow(const std::vector<Piece>& pieces, bool down, const Axes& to, SourceLocation at,
                std::optional<double> feed = std::nullopt);
    /// G40, G41, G42, G41.1, G42.1: starts collecting moves, or makes those collected.
    void cutter_mode(const Command& c);
    /// Throws when the block does what cannot happen while compensation is on.
    void comp_refuse(const Command& c) const;
    /// Collects a programmed move (pos_ -> to) while compensation is on.
    void comp_add(PlaneMove::Kind kind, const Arc* arc, bool rapid, const Axes& to,
                  SourceLocation at);
    /// Makes the collected moves along the tool center's path; the compensation ends.
    void comp_flush();

    const std::string* file_;
    const std::string& main_file_;
    Warn warn_;
    GcodeOptions options_;
    Parameters& parameters_;
    const ToolTable& tools_;
    RunBuilder runs_;
    PenEvidence evidence_;
    std::array<bool, kAxisCount> path_axis_{};

    Axes pos_{};              ///< machine coordinates; all 0 at the start
    bool z_known_ = false;    ///< false until a Z word: the pen counts as up (kZ)
    Axes g92_{};              ///< G92 offset: added to program coordinates
    std::size_t system_ = 0;  ///< G54 (0) .. G59.3 (8)
    Axes tool_offset_{};      ///< G43 / G43.1 tool length offsets
    Plane plane_ = kPlaneXY;  ///< G17, G18, G19
    Motion motion_ = Motion::kNone;
    bool inch_ = false;            ///< G20
    bool incremental_ = false;     ///< G91
    bool arc_incremental_ = true;  ///< G91.1 (LinuxCNC's default)
    bool inverse_time_ = false;    ///< G93
    double feed_ = 0;              ///< F in program units (mm or inch, degrees) per s; 0 until F
    double inverse_minutes_ = 0;   ///< G93: this block's move takes 1/F minutes
    bool spindle_ = false;         ///< M3/M4 given, no M5 since
    long selected_tool_ = -1;      ///< the last T word; -1: none
    long loaded_tool_ = -1;        ///< the tool the last M6 loaded; -1: none
    bool last_move_drew_ = false;  ///< kMotion: the pen is down
    std::optional<Vec2> last_cubic_control_;  ///< second control point of the last move, if G5
    bool retract_to_r_ = false;               ///< G99 (true) / G98 (false)
    /// Sticky cycle words as written (mm, seconds), and whether R and the bottom were given
    /// in G91 (then R counts from the initial level, the bottom from R).
    double cycle_r_ = 0, cycle_z_ = 0, cycle_q_ = 0, cycle_p_ = 0;
    bool cycle_r_incremental_ = false, cycle_z_incremental_ = false;
    Motion last_cycle_ = Motion::kNone;    ///< the cycle of the series, kNone out of one
    std::optional<double> cycle_initial_;  ///< the series' initial level on the drill axis

    /// The modes M70 and M73 save and M72 restores (LinuxCNC's list, what this reader has).
    struct ModalState {
        bool inch = false, incremental = false, arc_incremental = true, inverse_time = false;
        Plane plane = kPlaneXY;
        double feed = 0;
        std::size_t system = 0;
        Axes tool_offset{};
        bool retract_to_r = false, spindle = false;
        std::uint8_t outputs = 0;  ///< the spindle's and the coolant's (a machine's M3-M9)
        CornerMode corners = CornerMode::kBlend;
        double blend_tolerance = 0;
    };
    ModalState modal_state() const;
    void restore(const ModalState& s);
    /// M70, M71, M72, M73.
    void modal_state_code(const Command& c);
    void machine_functions(const Command& c);
    std::optional<ModalState> saved_state_;  ///< M70's
    std::size_t call_depth_ = 0;
    /// M73's, by the call depth that saved it (restored when that call returns).
    std::vector<std::pair<std::size_t, ModalState>> call_states_;

    /// A programmed move collected under G41/G42.
    struct CompMove {
        PlaneMove plane;  ///< in XY; source: its index
        Axes from{}, to{};
        bool rapid = false;
        double feed = 0;  ///< mm/s along the path (feed moves)
        SourceLocation at;
    };
    struct CompState {
        CompSide side = CompSide::kLeft;
        double radius = 0;  ///< mm
        Axes start{};       ///< the tool center where compensation began
        SourceLocation at;  ///< the G41/G42
        std::vector<CompMove> moves;
    };
    std::optional<CompState> comp_;

    struct NurbsPoint {
        Vec2 at;
        double weight = 1;
    };
    std::vector<NurbsPoint> nurbs_;  ///< G5.2 control points so far (the first: the start)
    int nurbs_order_ = 0;            ///< G5.2 L
    SourceLocation nurbs_at_;        ///< where the G5.2 is
    Axes nurbs_start_{};             ///< where the G5.2 curve starts
};

}  // namespace pathstream::host::gcode
