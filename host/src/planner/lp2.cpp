// The two-variable linear programs of a TOPP-RA step, solved exactly: every row bounds y by an
// affine function of x, so the feasible x form an interval [0, x*] whose end is the smallest
// crossing of a lower and an upper bound (O(rows^2), rows <= 4 * axes + 2).
#include "lp2.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include "vec.hpp"

namespace pathstream::host::planner_detail {
namespace {

struct Bound {
    double p, r;  // y >= p + r x (lower) or y <= p + r x (upper)
};

constexpr std::size_t kMaxBounds = 4 * kAxesMax + 4;

/// True when row's y coefficient is negligible against its x coefficient at this scale.
bool x_only(const LpRow& row) {
    return row.d == 0 || std::fabs(row.d) < 1e-13 * std::fabs(row.c);
}

}  // namespace

double lp_max_x(const LpRow* rows, std::size_t count, double x_max, double y_lo, double y_hi) {
    std::array<Bound, kMaxBounds> lower, upper;
    std::size_t nl = 0, nu = 0;
    lower[nl++] = {y_lo, 0};
    upper[nu++] = {y_hi, 0};
    double x = x_max;
    for (std::size_t m = 0; m < count && nl < kMaxBounds; ++m) {
        const LpRow& row = rows[m];
        if (x_only(row)) {
            if (row.c > 0)
                x = std::min(x, row.hi / row.c);
            else if (row.c < 0)
                x = std::min(x, row.lo / row.c);
            continue;
        }
        const double r = -row.c / row.d;
        if (row.d > 0) {
            lower[nl++] = {row.lo / row.d, r};
            upper[nu++] = {row.hi / row.d, r};
        } else {
            lower[nl++] = {row.hi / row.d, r};
            upper[nu++] = {row.lo / row.d, r};
        }
    }
    for (std::size_t i = 0; i < nl; ++i) {
        for (std::size_t j = 0; j < nu; ++j) {
            const double dr = lower[i].r - upper[j].r;
            if (dr > 0) x = std::min(x, (upper[j].p - lower[i].p) / dr);
        }
    }
    return std::max(x, 0.0);
}

bool lp_max_y(const LpRow* rows, std::size_t count, double x, double y_lo, double y_hi, double& y) {
    double lo = y_lo, hi = y_hi;
    bool feasible = true;
    for (std::size_t m = 0; m < count; ++m) {
        const LpRow& row = rows[m];
        if (x_only(row)) {
            const double v = row.c * x;
            if (v > row.hi * (1 + 1e-9) + 1e-12 || v < row.lo * (1 + 1e-9) - 1e-12)
                feasible = false;
            continue;
        }
        const double a = (row.lo - row.c * x) / row.d, b = (row.hi - row.c * x) / row.d;
        lo = std::max(lo, std::min(a, b));
        hi = std::min(hi, std::max(a, b));
    }
    if (hi < lo) {
        feasible = feasible && hi >= lo - 1e-9 * (std::fabs(lo) + 1e-12);
        y = std::clamp(lo, y_lo, y_hi);
        return feasible;
    }
    y = hi;
    return feasible;
}

}  // namespace pathstream::host::planner_detail
