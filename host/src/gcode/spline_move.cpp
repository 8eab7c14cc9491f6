// G5 (cubic) and G5.1 (quadratic) splines in the XY plane, as LinuxCNC reads them
// (docs/formats-gcode.md, "Splines").
#include "interpreter.hpp"

namespace pathstream::host::gcode {

void Interpreter::cubic(const Command& c, const Axes& to3, SourceLocation at) {
    if (plane_.normal != kZ) fail(at, "G5 needs the XY plane (G17)");
    const Vec2 to = in_plane(to3, kPlaneXY);
    const Word *i = c.value('I'), *j = c.value('J'), *p = c.value('P'), *q = c.value('Q');
    if (const Word* z = c.value('Z')) fail(z->at, "Z is not allowed with G5 (XY plane only)");
    if (!c.value('X') && !c.value('Y')) fail(at, "G5 needs X or Y (the end point)");
    if ((i != nullptr) != (j != nullptr)) {
        fail(i ? i->at : j->at, "G5 needs both I and J, or neither right after another G5");
    }
    if (!p || !q)
        fail(p ? p->at : q ? q->at : at, "G5 needs both P and Q (the second control point)");
    const Vec2 from = in_plane(pos_, kPlaneXY);
    Vec2 first;
    if (i) {
        first = from + Vec2{length(*i), length(*j)};
    } else if (last_cubic_control_) {
        first = 2.0 * from - *last_cubic_control_;  // reflection through the current point
    } else {
        fail(at,
             "G5 without I and J must follow another G5 (I and J give the first control point)");
    }
    const Vec2 second = to + Vec2{length(*p), length(*q)};
    follow(lift({Cubic{{from, first, second, to}}}, to3), pen_down(pos_[kZ], pos_[kZ]), to3, at);
    last_cubic_control_ = second;
}

void Interpreter::quadratic(const Command& c, const Axes& to3, SourceLocation at) {
    if (plane_.normal != kZ) fail(at, "G5.1 needs the XY plane (G17)");
    const Vec2 to = in_plane(to3, kPlaneXY);
    const Word *i = c.value('I'), *j = c.value('J');
    if (const Word* z = c.value('Z')) fail(z->at, "Z is not allowed with G5.1 (XY plane only)");
    if (!c.value('X') && !c.value('Y')) fail(at, "G5.1 needs X or Y (the end point)");
    const Vec2 offset{i ? length(*i) : 0.0, j ? length(*j) : 0.0};
    if (offset == Vec2{}) fail(at, "G5.1 needs a nonzero I or J (the control point)");
    const Vec2 from = in_plane(pos_, kPlaneXY);
    const Vec2 control = from + offset;
    // The quadratic's exact cubic form: control points 2/3 of the way to its control point.
    const Cubic piece{
        {from, from + (2.0 / 3.0) * (control - from), to + (2.0 / 3.0) * (control - to), to}};
    follow(lift({piece}, to3), pen_down(pos_[kZ], pos_[kZ]), to3, at);
}

}  // namespace pathstream::host::gcode
