// Modal state and block execution (docs/formats-gcode.md, "Modes" and "Moves").
#include "interpreter.hpp"

#include <cmath>
#include <sstream>

#include "pathstream/host/input_error.hpp"

namespace pathstream::host::gcode {

namespace {

constexpr double kMaxCoordinateMm = 1e6;  // as the JSON reader: catches unit mix-ups
constexpr double kMaxFeedMmPerMin = 1e6;

std::string number(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

}  // namespace

Interpreter::Interpreter(const std::string& file, const GcodeOptions& options)
    : file_(file), options_(options) {}

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
    if (options_.pen == PenControl::kSpindle) return spindle_;
    return z_known_ && from <= options_.z_down_max && to <= options_.z_down_max;
}

bool Interpreter::execute(const Command& c) {
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
    if (c.spindle_on) {
        spindle_ = *c.spindle_on;
        if (!spindle_ && options_.pen == PenControl::kSpindle) runs_.lift();
    }
    if (c.dwell) {
        const Word* p = c.value('P');
        if (!p) fail(c.dwell_at, "G4 needs P (the dwell time in seconds)");
        if (p->value < 0) fail(p->at, "G4 dwell time P must not be negative");
    }
    if (c.motion) motion_ = *c.motion;

    const bool axis_words = c.value('X') || c.value('Y') || c.value('Z');
    const bool arc_words = c.value('I') || c.value('J') || c.value('R');
    const bool arc_mode = motion_ == Motion::kArcCw || motion_ == Motion::kArcCcw;
    const bool moving =
        (c.motion && *c.motion != Motion::kNone) || axis_words || (arc_words && arc_mode);
    if (axis_words && motion_ == Motion::kNone) {
        const Word* w = c.value('X') ? c.value('X') : c.value('Y') ? c.value('Y') : c.value('Z');
        fail(w->at, c.motion ? "axis words cannot be used with G80"
                             : std::string("axis word ") + w->letter +
                                   " with no motion mode (give G0, G1, G2, G3, G5 or G5.1 first)");
    }
    check_words_used(c, motion_, moving);
    if (moving) move(c, motion_, c.motion ? c.motion_at : c.start);

    if (c.end_program) {
        runs_.lift();
        return false;
    }
    return true;
}

void Interpreter::check_words_used(const Command& c, Motion move, bool moving) const {
    const bool arc = moving && (move == Motion::kArcCw || move == Motion::kArcCcw);
    const bool spline = moving && (move == Motion::kCubic || move == Motion::kQuadratic);
    const bool cubic = moving && move == Motion::kCubic;
    const struct {
        char letter;
        bool used;
    } uses[] = {
        {'I', arc || spline},
        {'J', arc || spline},
        {'R', arc},
        {'P', arc || cubic || c.dwell || c.path_control},
        {'Q', cubic || c.path_control},
    };
    for (const auto& u : uses) {
        if (const Word* w = c.value(u.letter); w && !u.used) {
            fail(w->at,
                 std::string("word ") + u.letter + " is not used by any command in this block");
        }
    }
}

void Interpreter::move(const Command& c, Motion move, SourceLocation at) {
    Vec2 to = position_;
    double z_to = z_;
    auto axis = [&](char letter, double current) {
        const Word* w = c.value(letter);
        if (!w) return current;
        const double v = incremental_ ? current + length(*w) : length(*w);
        if (std::fabs(v) > kMaxCoordinateMm) {
            fail(w->at, std::string(1, letter) + " " + number(v) +
                            " mm is out of range (|value| <= " + number(kMaxCoordinateMm) + " mm)");
        }
        return v;
    };
    to.x = axis('X', position_.x);
    to.y = axis('Y', position_.y);
    z_to = axis('Z', z_);

    switch (move) {
        case Motion::kNone:
            break;  // not reached: execute() rejects axis words without a mode
        case Motion::kRapid:
            runs_.lift();
            position_ = to;
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
        for (const Cubic& piece : pieces) runs_.draw(piece, feed_, at);
    } else {
        runs_.lift();
    }
    position_ = to;
}

void Interpreter::line(Vec2 to, double z_to, SourceLocation at) {
    const Vec2 from = position_;
    const Cubic piece{
        {from, from + (1.0 / 3.0) * (to - from), from + (2.0 / 3.0) * (to - from), to}};
    follow({piece}, pen_down(z_, z_to), to, at);
}

Path Interpreter::finish() {
    Path path;
    path.axes = 2;
    path.subpaths = runs_.finish();
    if (path.subpaths.empty()) {
        throw InputError(
            file_, {},
            options_.pen == PenControl::kZ
                ? "no pen-down moves (the pen is down during G1, G2, G3, G5 and G5.1 moves at Z "
                  "<= " +
                      number(options_.z_down_max) + " mm)"
                : "no pen-down moves (the pen is down during G1, G2, G3, G5 and G5.1 moves between "
                  "M3 or M4 and M5)");
    }
    return path;
}

}  // namespace pathstream::host::gcode
