// The two-variable linear programs of a TOPP-RA step, solved exactly (lp2.cpp).
#pragma once

#include <cstddef>

namespace pathstream::host::planner_detail {

/// Max x in [0, x_max] such that some y in [y_lo, y_hi] satisfies lo_m <= c_m x + d_m y <= hi_m
/// for every row (each row must contain the origin: lo_m <= 0 <= hi_m, and y_lo <= 0 <= y_hi).
struct LpRow {
    double c, d, lo, hi;
};
double lp_max_x(const LpRow* rows, std::size_t count, double x_max, double y_lo, double y_hi);
/// Max y in [y_lo, y_hi] for a given x; returns false (and y = the least violating value) when
/// no y satisfies the rows.
bool lp_max_y(const LpRow* rows, std::size_t count, double x, double y_lo, double y_hi, double& y);

}  // namespace pathstream::host::planner_detail
