// The block's target point: axis words under G90/G91 and the offsets, or polar @ ^
// (docs/formats-gcode.md, "Moves and modes" and "Polar coordinates").
#include <cmath>
#include <numbers>
#include <sstream>

#include "interpreter.hpp"

namespace pathstream::host::gcode {

namespace {}  // namespace

Axes Interpreter::targets(const Command& c, bool machine_coordinates) const {
    Axes to = pos_;
    for (std::size_t a = 0; a < kAxisCount; ++a) {
        const Word* w = c.value(kAxisLetters[a]);
        if (!w) continue;
        if (!on_path(a) && a != kZ) {
            fail(w->at, std::string("axis ") + w->letter + " is not one of this machine's axes (" +
                            options_.axes + ")");
        }
        const double v = incremental_ ? pos_[a] + axis_value(*w, a)
                                      : axis_value(*w, a) + (machine_coordinates ? 0 : offset(a));
        if (std::fabs(v) > kMaxCoordinateMm) {
            const char* unit = is_rotary(a) ? "" : " mm";
            fail(w->at, std::string(1, w->letter) + " " + number_text(v) + unit +
                            " is out of range (|value| <= " + number_text(kMaxCoordinateMm) + unit +
                            ")");
        }
        to[a] = v;
    }
    if (c.polar_distance || c.polar_angle) {
        // As LinuxCNC: polar about the program's XY origin; in G91 @ and ^ add to the current
        // point's distance and angle.
        const Word* at = c.polar_distance ? &*c.polar_distance : &*c.polar_angle;
        if (c.value('X') || c.value('Y')) {
            fail(at->at, "polar coordinates (@ ^) and X or Y in one block");
        }
        if (plane_.normal != kZ) fail(at->at, "polar coordinates need the XY plane (G17)");
        if (machine_coordinates) fail(at->at, "polar coordinates with G53");
        const double x0 = pos_[kX] - offset(kX), y0 = pos_[kY] - offset(kY);
        const double r0 = std::hypot(x0, y0), a0 = std::atan2(y0, x0) * 180 / std::numbers::pi;
        if (r0 == 0 && (incremental_ || !c.polar_angle)) {
            fail(at->at, incremental_ ? "incremental polar coordinates at the origin: the angle "
                                        "is undefined there"
                                      : "polar coordinates at the origin need ^ (the angle)");
        }
        double r = r0, angle = a0;
        if (c.polar_distance) r = (incremental_ ? r0 : 0) + length(*c.polar_distance);
        if (c.polar_angle) angle = (incremental_ ? a0 : 0) + c.polar_angle->value;
        const double rad = angle * std::numbers::pi / 180;
        to[kX] = r * std::cos(rad) + offset(kX);
        to[kY] = r * std::sin(rad) + offset(kY);
        if (std::fabs(to[kX]) > kMaxCoordinateMm || std::fabs(to[kY]) > kMaxCoordinateMm) {
            fail(at->at, "polar point is out of range (|value| <= " +
                             number_text(kMaxCoordinateMm) + " mm)");
        }
    }
    return to;
}

}  // namespace pathstream::host::gcode
