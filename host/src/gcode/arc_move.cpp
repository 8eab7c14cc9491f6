// G2/G3 in the plane G17/G18/G19 selects: the center from the plane's offsets (I J, K I, J K;
// absolute under G90.1) or from R, LinuxCNC's checks on it, then Bezier pieces, with the
// normal axis linear in the angle (a helix) (docs/formats-gcode.md, "Arcs").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "arc.hpp"
#include "interpreter.hpp"

namespace pathstream::host::gcode {

namespace {

// LinuxCNC's defaults (interp_internal.hh): radii below this are zero; an R arc may be this
// much too short for its chord.
constexpr double kRadiusToleranceMm = 0.00005 * 25.4;
// LinuxCNC's defaults for how far the end may be off the start's circle
// (CENTER_ARC_RADIUS_TOLERANCE_MM / _INCH and SPIRAL_RELATIVE_TOLERANCE in interp_internal.hh),
// in the program's units: enough for end points and centers rounded to 0.01 mm or 0.001 in.
constexpr double kSpiralToleranceMm = 2 * 0.01 * std::numbers::sqrt2;
constexpr double kSpiralToleranceInch = 2 * 0.001 * std::numbers::sqrt2;
constexpr double kSpiralRelativeTolerance = 0.001;
// arc_data_ijk refuses any difference above this many times the small bound, relative or not.
constexpr double kSpiralHardLimitFactor = 100;
constexpr int kMaxTurns = 100;

std::string fixed(double v, int decimals) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
    return buffer;
}

}  // namespace

// LinuxCNC's arc_data_ijk: a large difference always fails; a small one only when it is also
// large relative to the radius, so tiny arcs rounded to a few decimals still pass.
void Interpreter::check_end_radius(double r0_mm, double r1_mm, SourceLocation at) const {
    const double abs_err = std::fabs(r0_mm - r1_mm);
    const double rel_err = abs_err / std::max(r0_mm, r1_mm);
    const double small_bound = inch_ ? kSpiralToleranceInch * 25.4 : kSpiralToleranceMm;
    const double large_bound = kSpiralHardLimitFactor * small_bound;
    const bool too_far = abs_err > large_bound;
    if (!too_far && !(abs_err > small_bound && rel_err > kSpiralRelativeTolerance)) return;
    const double unit = scale();
    const char* unit_name = inch_ ? " in" : " mm";
    auto in_units = [&](double mm) { return fixed(mm / unit, 6) + unit_name; };
    const std::string why = too_far ? "more than " + in_units(large_bound)
                                    : "more than " + in_units(small_bound) +
                                          " and more than 0.1% (" + fixed(rel_err * 100, 4) + "%)";
    fail(at, "radius to end of arc differs from radius to start: " + in_units(r0_mm) + " vs " +
                 in_units(r1_mm) + ", difference " + in_units(abs_err) + " is " + why);
}

void Interpreter::arc(const Command& c, Motion move, const Axes& to3, SourceLocation at) {
    const char* name = move == Motion::kArcCw ? "G2" : "G3";
    const Plane& pl = plane_;
    for (const char letter : {'I', 'J', 'K'}) {
        if (const Word* w = c.value(letter);
            w && letter != pl.first_offset && letter != pl.second_offset) {
            fail(w->at, std::string(1, letter) + " is no center offset of a " + pl.name +
                            " arc (it takes " + pl.first_offset + " and " + pl.second_offset + ")");
        }
    }
    for (const std::size_t axis : {pl.first, pl.second}) {
        if (!on_path(axis)) {
            fail(at, std::string(pl.name) + " arcs move " + kAxisLetters[axis] +
                         ", which is not one of this machine's axes (" + options_.axes + ")");
        }
    }
    if (!on_path(pl.normal) && to3[pl.normal] != pos_[pl.normal]) {
        const Word* w = c.value(kAxisLetters[pl.normal]);
        fail(w ? w->at : at, std::string(1, kAxisLetters[pl.normal]) + " changes during " + name +
                                 " but is not a motion axis here (a helix needs a " +
                                 kAxisLetters[pl.normal] + " axis)");
    }
    const Word *i = c.value(pl.first_offset), *j = c.value(pl.second_offset), *r = c.value('R'),
               *p = c.value('P');
    const Vec2 from = in_plane(pos_, pl), to = in_plane(to3, pl);
    const std::string offsets = std::string(1, pl.first_offset) + " and " + pl.second_offset;
    if (r && (i || j))
        fail(r->at, "give either " + offsets + " (the center) or R (the radius), not both");
    if (!r && !i && !j)
        fail(at, std::string(name) + " needs " + offsets + " (the center) or R (the radius)");

    int turns = 1;
    if (p) {
        if (p->value != std::floor(p->value) || p->value < 1 || p->value > kMaxTurns) {
            fail(p->at, "P (number of turns) must be a whole number from 1 to " +
                            std::to_string(kMaxTurns));
        }
        turns = static_cast<int>(p->value);
    }

    Vec2 center;
    if (r) {
        const double radius = length(*r);
        if (to == from) {
            fail(r->at, "R arc with the end point equal to the start point (use " + offsets +
                            " for a full circle)");
        }
        // As LinuxCNC's arc_data_r: the center lies on the chord's perpendicular bisector; R < 0
        // asks for the arc of more than 180 degrees.
        const double abs_radius = std::fabs(radius);
        if (abs_radius < kRadiusToleranceMm) fail(r->at, "zero-radius arc (R" + r->text + ")");
        const Vec2 mid = 0.5 * (from + to);
        double half = std::hypot(to.x - mid.x, to.y - mid.y);
        if (half - abs_radius > kRadiusToleranceMm) {
            fail(r->at, "arc radius R" + r->text + " is too small to reach the end point (" +
                            "half the chord is " + fixed(half, 4) + " mm)");
        }
        if (half / abs_radius > 1 - 1e-12) half = abs_radius;
        const bool right = (move == Motion::kArcCw) == (radius > 0);
        const double theta = std::atan2(to.y - from.y, to.x - from.x) +
                             (right ? -std::numbers::pi / 2 : std::numbers::pi / 2);
        const double offset = abs_radius * std::cos(std::asin(half / abs_radius));
        center = mid + offset * Vec2{std::cos(theta), std::sin(theta)};
    } else {
        if (arc_incremental_) {
            center = from + Vec2{i ? length(*i) : 0.0, j ? length(*j) : 0.0};
        } else {
            if (!i || !j) {
                fail(i ? i->at : j->at,
                     std::string(name) + " with absolute centers (G90.1) needs both " + offsets);
            }
            // G90.1: the center in program coordinates of the plane's axes.
            center = Vec2{length(*i) + offset(pl.first), length(*j) + offset(pl.second)};
        }
        const double r0 = std::hypot(from.x - center.x, from.y - center.y);
        const double r1 = std::hypot(to.x - center.x, to.y - center.y);
        if (r0 < kRadiusToleranceMm || r1 < kRadiusToleranceMm) {
            fail(at, "zero-radius arc (the center is at the start or end point)");
        }
        check_end_radius(r0, r1, at);
    }

    // G2 is clockwise seen from the plane's positive normal (LinuxCNC's G18 included: its
    // first axis is Z, so the view is from +Y).
    const bool ccw = move == Motion::kArcCcw;
    double sweep = 0;
    if (to == from) {
        sweep = ccw ? 2 * std::numbers::pi : -2 * std::numbers::pi;
    } else {
        sweep = std::atan2(to.y - center.y, to.x - center.x) -
                std::atan2(from.y - center.y, from.x - center.x);
        if (ccw && sweep <= 0) sweep += 2 * std::numbers::pi;
        if (!ccw && sweep >= 0) sweep -= 2 * std::numbers::pi;
    }
    sweep += (ccw ? 2 : -2) * std::numbers::pi * (turns - 1);

    if (!(std::fabs(center.x) <= 1e6) || !(std::fabs(center.y) <= 1e6)) {
        fail(at, "arc center is out of range (|value| <= 1e+06 mm)");
    }
    Arc geometry{from, to, center, sweep};
    if (comp_) {
        if (turns > 1) fail(p->at, "P (turns) above 1 while cutter radius compensation is on");
        comp_add(PlaneMove::kArc, &geometry, false, to3, at);
        return;
    }
    if (on_path(pl.normal)) geometry.rise = to3[pl.normal] - pos_[pl.normal];
    follow(lift(arc_to_cubics(geometry, options_.arc_tolerance_mm), to3),
           pen_down(pos_[kZ], to3[kZ]), to3, at);
}

}  // namespace pathstream::host::gcode
