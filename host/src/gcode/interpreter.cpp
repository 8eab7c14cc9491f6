// Modal state and block execution (docs/formats-gcode.md, "Modes" and "Moves").
#include "interpreter.hpp"

#include <cmath>
#include <numbers>
#include <sstream>

#include "pathstream/machine/input_error.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host::gcode {

namespace {

// LinuxCNC takes any F and the machine's limits govern; this bounds only nonsense.
constexpr double kMaxFeedMmPerMin = 1e9;

std::vector<std::size_t> axis_indices(const std::string& letters) {
    std::vector<std::size_t> indices;
    for (const char c : letters) indices.push_back(axis_index(c));
    return indices;
}

}  // namespace

Interpreter::Interpreter(const std::string& file, const GcodeOptions& options,
                         Parameters& parameters, const ToolTable& tools)
    : file_(&file),
      main_file_(file),
      options_(options),
      parameters_(parameters),
      tools_(tools),
      runs_(axis_indices(options.axes), options.budget.pieces) {
    for (const char c : options.axes) path_axis_[axis_index(c)] = true;
    parameters_.set(ParameterRef{5220, {}}, 1);  // G54
}

void Interpreter::fail(SourceLocation at, const std::string& message) const {
    throw InputError(*file_, at, message);
}

double Interpreter::length(const Word& w) const {
    const double mm = w.value * scale();
    if (std::fabs(mm) > kMaxCoordinateMm) {
        fail(w.at, std::string(1, w.letter) + " " + number_text(mm) +
                       " mm is out of range (|value| <= " + number_text(kMaxCoordinateMm) + " mm)");
    }
    return mm;
}

double Interpreter::axis_value(const Word& w, std::size_t axis) const {
    if (!is_rotary(axis)) return length(w);
    if (std::fabs(w.value) > kMaxCoordinateMm) {
        fail(w.at, std::string(1, w.letter) + " " + number_text(w.value) +
                       " degrees is out of range (|value| <= " + number_text(kMaxCoordinateMm) +
                       ")");
    }
    return w.value;
}

void Interpreter::check_point(const Axes& p, SourceLocation at) const {
    for (std::size_t a = 0; a < kAxisCount; ++a) {
        if (!(std::fabs(p[a]) <= kMaxCoordinateMm)) {
            const char* unit = is_rotary(a) ? "" : " mm";
            fail(at, std::string("curve point ") + kAxisLetters[a] + " " + number_text(p[a]) +
                         unit + " is out of range (|value| <= " + number_text(kMaxCoordinateMm) +
                         unit + ")");
        }
    }
}

bool Interpreter::pen_down(double from, double to) const {
    switch (options_.pen) {
        case PenControl::kSpindle:
            return spindle_;
        case PenControl::kMotion:
        case PenControl::kMachine:
            return true;
        default:
            return z_known_ && from <= options_.z_down_max && to <= options_.z_down_max;
    }
}

bool Interpreter::pen_down_now() const {
    switch (options_.pen) {
        case PenControl::kSpindle:
            return spindle_;
        case PenControl::kMotion:
        case PenControl::kMachine:
            return last_move_drew_;
        default:
            return z_known_ && pos_[kZ] <= options_.z_down_max;
    }
}

void Interpreter::feed_word(const Command& c) {
    if (c.inverse_time) {
        if (*c.inverse_time != inverse_time_) feed_ = 0;  // as LinuxCNC: a new mode needs F
        inverse_time_ = *c.inverse_time;
    }
    inverse_minutes_ = 0;
    const Word* f = c.value('F');
    if (!f) return;
    if (inverse_time_) {
        // G93: the move takes 1/F minutes; F is per block, not modal.
        if (!(f->value > 0) || !std::isfinite(1 / f->value)) {
            fail(f->at, "inverse time feed F" + f->text + " must be positive (G93: 1/F minutes)");
        }
        inverse_minutes_ = 1 / f->value;
        return;
    }
    const double mm_per_min = f->value * scale();
    if (!(mm_per_min > 0) || mm_per_min > kMaxFeedMmPerMin) {
        fail(f->at, "feed F" + f->text +
                        " is out of range (0 < F <= " + number_text(kMaxFeedMmPerMin) + " mm/min)");
    }
    feed_ = f->value / 60.0;  // program units: scaled per move, rotary-only moves are not
}

bool Interpreter::execute(const Command& c) {
    if (!nurbs_.empty() && ((c.motion && *c.motion != Motion::kNurbs) ||
                            (c.non_modal != NonModal::kNone && !c.nurbs_end))) {
        fail(c.motion ? c.motion_at : c.non_modal_at,
             "the G5.2 curve must end with G5.3 before other motion or G4, G10, G28, G30, G53, "
             "G92");
    }
    comp_refuse(c);
    modal_state_code(c);
    if (c.inch) inch_ = *c.inch;
    if (c.plane) plane_ = *c.plane;
    if (c.incremental) incremental_ = *c.incremental;
    if (c.arc_incremental) arc_incremental_ = *c.arc_incremental;
    feed_word(c);
    if (const Word* t = c.value('T')) {
        if (t->value != std::floor(t->value) || t->value < 0 || t->value > 1e9)
            fail(t->at, "T must be a whole tool number >= 0");
        selected_tool_ = static_cast<long>(t->value);
    }
    if (c.path_control) path_control(c);
    // LinuxCNC runs M6 before the spindle and coolant codes of its block: with a tool change
    // they follow its pause.
    if (machine() && !c.tool_change) machine_functions(c);
    if (c.spindle_on) {
        spindle_ = *c.spindle_on;
        if (spindle_) evidence_.spindle = true;
        if (!spindle_ && options_.pen == PenControl::kSpindle) runs_.lift();
    }
    if (c.non_modal == NonModal::kDwell) {
        const Word* p = c.value('P');
        if (!p) fail(c.non_modal_at, "G4 needs P (the dwell time in seconds)");
        if (p->value < 0) fail(p->at, "G4 dwell time P must not be negative");
        // A dwell ends the stroke: the next subpath starts with it.
        const bool down = pen_down_now();
        runs_.lift();
        runs_.dwell_next(p->value, down);
    }
    offsets_modes(c);
    cutter_mode(c);
    if (c.retract_to_r) retract_to_r_ = *c.retract_to_r;
    if (c.nurbs_end) {
        if (nurbs_.empty()) fail(c.start, "G5.3 without a G5.2 curve to end");
        nurbs_end(c.start);
        motion_ = Motion::kNone;
    }
    if (c.motion) {
        if (!is_cycle(*c.motion)) {
            last_cycle_ = Motion::kNone;  // the series of cycle blocks ends
            cycle_initial_.reset();
        }
        motion_ = *c.motion;
        if (motion_ == Motion::kNurbs && nurbs_.empty()) nurbs_at_ = c.motion_at;
    }

    const Word* first_axis = nullptr;
    for (const char letter : kAxisLetters) {
        if (const Word* w = c.value(letter); w && !first_axis) first_axis = w;
    }
    if (!first_axis && c.polar_distance) first_axis = &*c.polar_distance;
    if (!first_axis && c.polar_angle) first_axis = &*c.polar_angle;
    const bool axis_words = first_axis != nullptr;
    const bool uses_axes = c.non_modal == NonModal::kSetOffset || c.non_modal == NonModal::kHome ||
                           c.non_modal == NonModal::kHome2 ||
                           c.non_modal == NonModal::kSetCoordinates ||
                           c.tool_length == ToolLength::kDynamic;
    if (uses_axes && c.motion && *c.motion != Motion::kNone) {
        fail(c.motion_at,
             "G10, G28, G30, G43.1 and G92 use the block's axis words: no motion code with them");
    }
    if (c.non_modal != NonModal::kNone && c.non_modal != NonModal::kDwell &&
        c.non_modal != NonModal::kMachineCoords) {
        non_modal(c);
    }
    const bool arc_words = c.value('I') || c.value('J') || c.value('K') || c.value('R');
    const bool arc_mode = motion_ == Motion::kArcCw || motion_ == Motion::kArcCcw;
    const bool moving = !uses_axes && ((c.motion && *c.motion != Motion::kNone) || axis_words ||
                                       (arc_words && arc_mode));
    if (!uses_axes && axis_words && motion_ == Motion::kNone) {
        fail(first_axis->at,
             c.motion || c.nurbs_end
                 ? "axis words cannot be used with " + std::string(c.nurbs_end ? "G5.3" : "G80")
                 : std::string("axis word ") + first_axis->letter +
                       " with no motion mode (give G0, G1, G2, G3, G5, G5.1, G5.2 or a canned "
                       "cycle first)");
    }
    if (c.non_modal == NonModal::kMachineCoords &&
        (!moving || (motion_ != Motion::kRapid && motion_ != Motion::kLine) || incremental_)) {
        fail(c.non_modal_at, "G53 needs a G0 or G1 move in absolute mode (G90) in its block");
    }
    check_words_used(c, motion_, moving);
    if (moving) move(c, motion_, c.motion ? c.motion_at : c.start);

    if (c.value('Z') && z_known_)
        (pos_[kZ] <= options_.z_down_max ? evidence_.z_low : evidence_.z_high) = true;
    // M6 after the block's moves (LinuxCNC runs it before them; a change pauses with the tool
    // where the program last left it, which is the same place when M6 has a block of its own).
    const bool pause = c.pause || c.tool_change;
    if (pause || c.end_program) runs_.lift();
    if (c.tool_change && machine()) {
        // As LinuxCNC, a tool change stops the spindle (the coolant stays as it was).
        runs_.set_outputs(
            static_cast<std::uint8_t>(runs_.outputs() & ~(kOutputSpindle | kOutputSpindleReverse)));
    }
    if (pause) runs_.pause_next(pause_note(c));
    if (c.tool_change && machine()) machine_functions(c);
    if (c.tool_change) load_tool();
    if (c.set_tool) {
        const Word* q = c.value('Q');
        if (!q || q->value != std::floor(q->value) || q->value < 0) {
            fail(q ? q->at : c.start, "M61 needs Q, a whole tool number >= 0");
        }
        selected_tool_ = static_cast<long>(q->value);
        load_tool();
    }
    if (c.end_program) {
        if (!nurbs_.empty()) fail(c.start, "program ends inside a G5.2 curve (no G5.3)");
        if (comp_) comp_flush();  // as LinuxCNC, the program's end turns compensation off
        return false;
    }
    return true;
}

// M3/M4/M5 and M7/M8/M9 on a machine: the spindle's and the coolant's outputs from here on.
void Interpreter::machine_functions(const Command& c) {
    unsigned o = runs_.outputs();
    if (c.spindle_on) {
        o &= ~unsigned{kOutputSpindle | kOutputSpindleReverse};
        if (*c.spindle_on) o |= kOutputSpindle | (c.spindle_reverse ? kOutputSpindleReverse : 0u);
    }
    if (c.coolant_off) o &= ~unsigned{kOutputMist | kOutputFlood};
    if (c.mist) o |= kOutputMist;
    if (c.flood) o |= kOutputFlood;
    runs_.set_outputs(static_cast<std::uint8_t>(o));
}

Interpreter::ModalState Interpreter::modal_state() const {
    return ModalState{inch_,
                      incremental_,
                      arc_incremental_,
                      inverse_time_,
                      plane_,
                      feed_,
                      system_,
                      tool_offset_,
                      retract_to_r_,
                      spindle_,
                      runs_.outputs(),
                      runs_.corner_mode(),
                      runs_.blend_tolerance()};
}

void Interpreter::restore(const ModalState& s) {
    inch_ = s.inch;
    incremental_ = s.incremental;
    arc_incremental_ = s.arc_incremental;
    inverse_time_ = s.inverse_time;
    plane_ = s.plane;
    feed_ = s.feed;
    system_ = s.system;
    parameters_.set(ParameterRef{5220, {}}, static_cast<double>(system_ + 1));
    tool_offset_ = s.tool_offset;
    retract_to_r_ = s.retract_to_r;
    spindle_ = s.spindle;
    if (machine()) runs_.set_outputs(s.outputs);
    runs_.set_corners(s.corners, s.blend_tolerance);
}

// LinuxCNC's M70-M73, at the start of the block (LinuxCNC saves after the block's F, S, T
// and spindle codes; a block that both saves and sets those is rare).
void Interpreter::modal_state_code(const Command& c) {
    switch (c.modal_state) {
        case 70:
            saved_state_ = modal_state();
            break;
        case 71:
            saved_state_.reset();
            break;
        case 72:
            if (!saved_state_) fail(c.modal_state_at, "M72 without a state saved by M70");
            restore(*saved_state_);
            break;
        case 73:
            if (call_depth_ == 0) fail(c.modal_state_at, "M73 outside a subroutine");
            call_states_.emplace_back(call_depth_, modal_state());
            break;
        default:
            break;
    }
}

void Interpreter::leave_call() {
    if (!call_states_.empty() && call_states_.back().first == call_depth_) {
        restore(call_states_.back().second);
        call_states_.pop_back();
    }
    if (call_depth_ > 0) --call_depth_;
}

std::string Interpreter::pause_note(const Command& c) const {
    const std::string line = ", line " + std::to_string(c.pause_at.line);
    if (!c.tool_change)
        return std::string(c.pallet_change   ? "pallet change (M60)"
                           : c.optional_stop ? "optional stop (M1)"
                                             : "program stop (M0)") +
               line;
    if (selected_tool_ < 0) return "tool change (M6, no T given)" + line;
    std::string note = "tool change to T" + std::to_string(selected_tool_);
    if (const ToolEntry* t = tools_.find(selected_tool_); t && !t->comment.empty())
        note += " (" + t->comment + ")";
    return note + line;
}

void Interpreter::path_control(const Command& c) {
    double tolerance = 0;
    if (c.path_control == CornerMode::kBlend) {
        // G64 P: the most a rounded corner may depart from the programmed vertex; G64 Q (naive
        // CAM: merging nearly collinear moves) has no counterpart, the planner keeps every move.
        if (const Word* p = c.value('P')) {
            if (!(p->value >= 0)) fail(p->at, "G64 blend tolerance P must not be negative");
            tolerance = length(*p);
        }
        if (const Word* q = c.value('Q'); q && !(q->value >= 0)) {
            fail(q->at, "G64 naive CAM tolerance Q must not be negative");
        }
    }
    runs_.set_corners(*c.path_control, tolerance);
}

void Interpreter::check_words_used(const Command& c, Motion move, bool moving) const {
    const bool arc = moving && (move == Motion::kArcCw || move == Motion::kArcCcw);
    const bool spline = moving && (move == Motion::kCubic || move == Motion::kQuadratic);
    const bool cubic = moving && move == Motion::kCubic;
    const bool nurbs = moving && move == Motion::kNurbs;
    const bool cycle = moving && is_cycle(move);
    const bool peck = cycle && (move == Motion::kPeck || move == Motion::kPeckChipBreak);
    const bool cycle_dwell = cycle && (move == Motion::kDrillDwell || move == Motion::kBoreDwell ||
                                       move == Motion::kBoreSpindleStop);
    const bool blending = c.path_control == CornerMode::kBlend;
    const bool g10 = c.non_modal == NonModal::kSetCoordinates;
    const struct {
        char letter;
        bool used;
    } uses[] = {
        {'I', arc || spline},
        {'J', arc || spline},
        {'K', arc},
        {'R', arc || cycle || g10},
        {'P', arc || cubic || nurbs || cycle_dwell || c.non_modal == NonModal::kDwell || blending ||
                  g10},
        {'Q', cubic || blending || peck || c.set_tool},
        {'L', nurbs || cycle || g10},
        {'H', c.tool_length == ToolLength::kTable},
        {'D', (c.cutter_comp && *c.cutter_comp != CutterComp::kOff) || c.spindle_speed_mode},
    };
    if (const Word* p = c.value('P');
        p && blending && (arc || cubic || nurbs || c.non_modal == NonModal::kDwell)) {
        fail(p->at,
             "word P would be used by G64 and by the block's other command: give G64 a block of "
             "its own");
    }
    for (const auto& u : uses) {
        if (const Word* w = c.value(u.letter); w && !u.used) {
            fail(w->at,
                 std::string("word ") + u.letter + " is not used by any command in this block");
        }
    }
}

void Interpreter::move(const Command& c, Motion move, SourceLocation at) {
    if (is_cycle(move)) {
        canned_cycle(c, move, at);
        return;
    }
    const Axes to = targets(c, c.non_modal == NonModal::kMachineCoords);
    const bool z_word = c.value('Z') != nullptr;
    switch (move) {
        case Motion::kRapid:
            travel(to, at);
            break;
        case Motion::kLine:
            line(to, at);
            break;
        case Motion::kArcCw:
        case Motion::kArcCcw:
            arc(c, move, to, at);
            break;
        case Motion::kCubic:
            cubic(c, to, at);
            break;
        case Motion::kQuadratic:
            quadratic(c, to, at);
            break;
        case Motion::kNurbs:
            nurbs_point(c, to, at);
            break;
        default:
            break;  // kNone: execute() rejects axis words without a mode
    }
    if (z_word) {
        pos_[kZ] = to[kZ];
        z_known_ = true;
    }
    if (move != Motion::kCubic) last_cubic_control_.reset();
}

Path Interpreter::finish(bool allow_empty) {
    if (comp_) comp_flush();
    Path path;
    path.axes = options_.axes.size();
    path.subpaths = runs_.finish();
    bool drawn = false;
    for (const Subpath& s : path.subpaths) drawn = drawn || !s.travel;
    if (!drawn && !allow_empty) {
        std::string why;
        switch (options_.pen) {
            case PenControl::kSpindle:
                why = "moves between M3 or M4 and M5";
                break;
            case PenControl::kMotion:
            case PenControl::kMachine:
                why = "moves (G0 travels)";
                break;
            default:
                why = "moves at Z <= " + number_text(options_.z_down_max) + " mm";
        }
        throw InputError(
            main_file_, {},
            "no pen-down moves (the pen is down during G1, G2, G3, G5, G5.1 and G5.2 " + why + ")");
    }
    return path;
}

}  // namespace pathstream::host::gcode
