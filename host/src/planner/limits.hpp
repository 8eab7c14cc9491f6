// The per-axis limits of one planning attempt: apart from the machine profile because a
// replan lowers them.
#pragma once

#include <vector>

namespace pathstream::host::planner_detail {

/// Per-axis limits of one planning attempt (mm/s, mm/s^2): the profile's, possibly lowered by
/// a replan.
struct Limits {
    std::vector<double> velocity, acceleration;
    /// mm/s^3 per axis, 0: no jerk limit (docs/planner.md §12). Empty: none on any axis.
    std::vector<double> jerk;
    /// Share of the jerk limit the jerk stage's filter plans with (lowered by replans).
    double jerk_share = 0.75;
    bool has_jerk() const {
        for (const double j : jerk) {
            if (j > 0) return true;
        }
        return false;
    }
};

}  // namespace pathstream::host::planner_detail
