// Modal state and block execution (docs/formats-gcode.md, "Modes" and "Moves").
#include "interpreter.hpp"

#include <cmath>
#include <sstream>

#include "pathstream/machine/input_error.hpp"

namespace pathstream::host::gcode {

namespace {

constexpr double kMaxCoordinateMm = 1e6;  // as the JSON reader: catches unit mix-ups
constexpr double kMaxFeedMmPerMin = 1e6;
// LinuxCNC's parameters for the G28 and G30 positions and the G92 offset (X, Y, Z).
constexpr long kG28Position = 5161;
constexpr long kG30Position = 5181;
constexpr long kG92Applied = 5210;
constexpr long kG92Offset = 5211;

// The shortest usual form of a number, for messages.
std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// A reference to numbered parameter #n.
ParameterRef numbered(long n) {
    return ParameterRef{n, {}};
}

}  // namespace

Interpreter::Interpreter(const std::string& file, const GcodeOptions& options,
                         Parameters& parameters)
    : file_(file), options_(options), parameters_(parameters) {}

void Interpreter::fail(SourceLocation at, const std::string& message) const {
    throw InputError(file_, at, message);
}

double Interpreter::length(const Word& w) const {
    const double mm = w.value * scale();
    if (std::fabs(mm) > kMaxCoordinateMm) {
        fail(w.at, std::string(1, w.letter) + " " + number(mm) +
                       " mm is out of range (|value| <= " + number(kMaxCoordinateMm) + " mm)");
    }
    return mm;
}

void Interpreter::check_point(Vec2 p, SourceLocation at) const {
    if (!(std::fabs(p.x) <= kMaxCoordinateMm) || !(std::fabs(p.y) <= kMaxCoordinateMm)) {
        fail(at, "curve point (" + number(p.x) + ", " + number(p.y) +
                     ") mm is out of range (|value| <= " + number(kMaxCoordinateMm) + " mm)");
    }
}

bool Interpreter::pen_down(double from, double to) const {
    switch (options_.pen) {
        case PenControl::kSpindle:
            return spindle_;
        case PenControl::kMotion:
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
            return last_move_drew_;
        default:
            return z_known_ && z_ <= options_.z_down_max;
    }
}

bool Interpreter::execute(const Command& c) {
    if (!nurbs_.empty() && ((c.motion && *c.motion != Motion::kNurbs) ||
                            (c.non_modal != NonModal::kNone && !c.nurbs_end))) {
        fail(c.motion ? c.motion_at : c.non_modal_at,
             "the G5.2 curve must end with G5.3 before other motion or G4, G28, G30, G53, G92");
    }
    if (c.inch) inch_ = *c.inch;
    if (c.incremental) incremental_ = *c.incremental;
    if (c.arc_incremental) arc_incremental_ = *c.arc_incremental;
    if (const Word* f = c.value('F')) {
        const double mm_per_min = f->value * scale();
        if (!(mm_per_min > 0) || mm_per_min > kMaxFeedMmPerMin) {
            fail(f->at, "feed F" + f->text +
                            " is out of range (0 < F <= " + number(kMaxFeedMmPerMin) + " mm/min)");
        }
        feed_ = mm_per_min / 60.0;
    }
    if (c.path_control) path_control(c);
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
    if (c.nurbs_end) {
        if (nurbs_.empty()) fail(c.start, "G5.3 without a G5.2 curve to end");
        nurbs_end(c.start);
        motion_ = Motion::kNone;
    }
    if (c.motion) {
        motion_ = *c.motion;
        if (motion_ == Motion::kNurbs && nurbs_.empty()) nurbs_at_ = c.motion_at;
    }

    const bool axis_words = c.value('X') || c.value('Y') || c.value('Z');
    const bool uses_axes = c.non_modal == NonModal::kSetOffset || c.non_modal == NonModal::kHome ||
                           c.non_modal == NonModal::kHome2;
    if (uses_axes && c.motion && *c.motion != Motion::kNone) {
        fail(c.motion_at, "G28, G30 and G92 use the block's axis words: no motion code with them");
    }
    if (c.non_modal != NonModal::kNone && c.non_modal != NonModal::kDwell &&
        c.non_modal != NonModal::kMachineCoords) {
        non_modal(c);
    }
    const bool arc_words = c.value('I') || c.value('J') || c.value('R');
    const bool arc_mode = motion_ == Motion::kArcCw || motion_ == Motion::kArcCcw;
    const bool moving = !uses_axes && ((c.motion && *c.motion != Motion::kNone) || axis_words ||
                                       (arc_words && arc_mode));
    if (!uses_axes && axis_words && motion_ == Motion::kNone) {
        const Word* w = c.value('X') ? c.value('X') : c.value('Y') ? c.value('Y') : c.value('Z');
        fail(w->at,
             c.motion || c.nurbs_end
                 ? "axis words cannot be used with " + std::string(c.nurbs_end ? "G5.3" : "G80")
                 : std::string("axis word ") + w->letter +
                       " with no motion mode (give G0, G1, G2, G3, G5, G5.1 or G5.2 first)");
    }
    if (c.non_modal == NonModal::kMachineCoords &&
        (!moving || (motion_ != Motion::kRapid && motion_ != Motion::kLine) || incremental_)) {
        fail(c.non_modal_at, "G53 needs a G0 or G1 move in absolute mode (G90) in its block");
    }
    check_words_used(c, motion_, moving);
    if (moving) move(c, motion_, c.motion ? c.motion_at : c.start);

    if (c.value('Z') && z_known_)
        (z_ <= options_.z_down_max ? evidence_.z_low : evidence_.z_high) = true;
    if (c.pause || c.end_program) runs_.lift();
    if (c.pause) runs_.pause_next();
    if (c.end_program) {
        if (!nurbs_.empty()) fail(c.start, "program ends inside a G5.2 curve (no G5.3)");
        return false;
    }
    return true;
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
    const bool blending = c.path_control == CornerMode::kBlend;
    const struct {
        char letter;
        bool used;
    } uses[] = {
        {'I', arc || spline},
        {'J', arc || spline},
        {'R', arc},
        {'P', arc || cubic || nurbs || c.non_modal == NonModal::kDwell || blending},
        {'Q', cubic || blending},
        {'L', nurbs},
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

void Interpreter::targets(const Command& c, Vec2& to, double& z_to, bool machine) const {
    auto axis = [&](char letter, double current, double offset) {
        const Word* w = c.value(letter);
        if (!w) return current;
        const double v = incremental_ ? current + length(*w) : length(*w) + (machine ? 0 : offset);
        if (std::fabs(v) > kMaxCoordinateMm) {
            fail(w->at, std::string(1, letter) + " " + number(v) +
                            " mm is out of range (|value| <= " + number(kMaxCoordinateMm) + " mm)");
        }
        return v;
    };
    to.x = axis('X', position_.x, offset_.x);
    to.y = axis('Y', position_.y, offset_.y);
    z_to = axis('Z', z_, z_offset_);
}

void Interpreter::travel(Vec2 to, double z_to) {
    runs_.lift();
    last_move_drew_ = false;
    position_ = to;
    z_ = z_to;
}

void Interpreter::non_modal(const Command& c) {
    // As LinuxCNC, these parameters are in the machine's units (mm here), whatever G20/G21.
    auto store_offset = [&] {
        parameters_.set(numbered(kG92Offset), offset_.x);
        parameters_.set(numbered(kG92Offset + 1), offset_.y);
        parameters_.set(numbered(kG92Offset + 2), z_offset_);
    };
    switch (c.non_modal) {
        case NonModal::kSetOffset: {
            if (!c.value('X') && !c.value('Y') && !c.value('Z')) {
                fail(c.non_modal_at, "G92 needs at least one of X, Y, Z");
            }
            // The current point gets the given coordinates: offset = machine - program.
            if (const Word* w = c.value('X')) offset_.x = position_.x - length(*w);
            if (const Word* w = c.value('Y')) offset_.y = position_.y - length(*w);
            if (const Word* w = c.value('Z')) {
                z_offset_ = z_ - length(*w);
                z_known_ = true;
            }
            store_offset();
            parameters_.set(numbered(kG92Applied), 1);
            break;
        }
        case NonModal::kClearOffset:
        case NonModal::kSuspendOffset:
            offset_ = {};
            z_offset_ = 0;
            if (c.non_modal == NonModal::kClearOffset) store_offset();
            parameters_.set(numbered(kG92Applied), 0);
            break;
        case NonModal::kRestoreOffset:
            offset_ = {*parameters_.get(numbered(kG92Offset)),
                       *parameters_.get(numbered(kG92Offset + 1))};
            z_offset_ = *parameters_.get(numbered(kG92Offset + 2));
            parameters_.set(numbered(kG92Applied), 1);
            break;
        case NonModal::kSetHome:
        case NonModal::kSetHome2: {
            const long base = c.non_modal == NonModal::kSetHome ? kG28Position : kG30Position;
            parameters_.set(numbered(base), position_.x);
            parameters_.set(numbered(base + 1), position_.y);
            parameters_.set(numbered(base + 2), z_);
            break;
        }
        case NonModal::kHome:
        case NonModal::kHome2: {
            // As LinuxCNC: through the given point, then to the stored position, both at rapid;
            // with axis words only those axes move.
            const long base = c.non_modal == NonModal::kHome ? kG28Position : kG30Position;
            const bool all = !c.value('X') && !c.value('Y') && !c.value('Z');
            Vec2 via = position_;
            double z_via = z_;
            targets(c, via, z_via, false);
            travel(via, z_via);
            auto home = [&](char letter, long n, double current) {
                if (!all && !c.value(letter)) return current;
                const double v = *parameters_.get(numbered(n));
                if (std::fabs(v) > kMaxCoordinateMm) {
                    fail(c.non_modal_at, "#" + std::to_string(n) + " " + number(v) +
                                             " mm is out of range (|value| <= " +
                                             number(kMaxCoordinateMm) + " mm)");
                }
                return v;
            };
            const Vec2 to{home('X', base, position_.x), home('Y', base + 1, position_.y)};
            const double z_to = home('Z', base + 2, z_);
            if (all || c.value('Z')) z_known_ = true;
            travel(to, z_to);
            break;
        }
        default:
            break;
    }
}

void Interpreter::move(const Command& c, Motion move, SourceLocation at) {
    Vec2 to = position_;
    double z_to = z_;
    targets(c, to, z_to, c.non_modal == NonModal::kMachineCoords);

    switch (move) {
        case Motion::kNone:
            break;  // not reached: execute() rejects axis words without a mode
        case Motion::kRapid:
            travel(to, z_);
            break;
        case Motion::kLine:
            line(to, z_to, at);
            break;
        case Motion::kArcCw:
        case Motion::kArcCcw: {
            const Word* z = c.value('Z');
            if (z && (!z_known_ || z_to != z_)) {
                fail(z->at, "helical arcs are not supported (Z changes during G2/G3)");
            }
            arc(c, move, to, at);
            break;
        }
        case Motion::kCubic:
            cubic(c, to, at);
            break;
        case Motion::kQuadratic:
            quadratic(c, to, at);
            break;
        case Motion::kNurbs:
            nurbs_point(c, to, at);
            break;
    }
    if (c.value('Z')) {
        z_ = z_to;
        z_known_ = true;
    }
    if (move != Motion::kCubic) last_cubic_control_.reset();
}

void Interpreter::follow(const std::vector<Cubic>& pieces, bool down, Vec2 to, SourceLocation at) {
    for (const Cubic& piece : pieces) {
        for (const Vec2& p : piece.p) check_point(p, at);
    }
    if (down) {
        for (const Cubic& piece : pieces) runs_.draw(piece, feed_, at, file_);
        runs_.end_block();
    } else {
        runs_.lift();
    }
    last_move_drew_ = down;
    position_ = to;
}

void Interpreter::line(Vec2 to, double z_to, SourceLocation at) {
    const Vec2 from = position_;
    follow({line_piece(from, to)}, pen_down(z_, z_to), to, at);
}

Path Interpreter::finish(bool allow_empty) {
    Path path;
    path.axes = 2;
    path.subpaths = runs_.finish();
    if (path.subpaths.empty() && !allow_empty) {
        std::string why;
        switch (options_.pen) {
            case PenControl::kSpindle:
                why = "moves between M3 or M4 and M5";
                break;
            case PenControl::kMotion:
                why = "moves (G0 travels)";
                break;
            default:
                why = "moves at Z <= " + number(options_.z_down_max) + " mm";
        }
        throw InputError(
            file_, {},
            "no pen-down moves (the pen is down during G1, G2, G3, G5, G5.1 and G5.2 " + why + ")");
    }
    return path;
}

}  // namespace pathstream::host::gcode
