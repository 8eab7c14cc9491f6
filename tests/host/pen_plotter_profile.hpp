// The pen plotter's machine profile (examples/machines/pen_plotter.json) for planner tests.
#pragma once

#include "pathstream/machine/machine.hpp"

namespace pathstream::host::test {

/// 250 mm/s and 3000 mm/s^2 per axis, 1 kHz, 8 ticks per span, 1 um LSB, feed 80 mm/s,
/// travel 200 mm/s, 5 um chord tolerance, pen delays 80 ms down and 60 ms up.
inline MachineProfile pen_plotter() {
    MachineProfile p;
    p.axes.push_back({"x", 250, 3000});
    p.axes.push_back({"y", 250, 3000});
    p.feed = 80;
    p.travel_feed = 200;
    p.pen_down_delay = 0.08;
    p.pen_up_delay = 0.06;
    return p;
}

}  // namespace pathstream::host::test
