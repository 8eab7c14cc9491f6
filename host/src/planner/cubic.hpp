// A Bezier segment in the flat form the planner evaluates (point, derivatives, arc length),
// with its axis count so that the hot loops skip the axes not in use.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

#include "pathstream/host/geometry.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// A Bezier segment in flat form.
struct Cubic {
    std::array<Vec, 4> p{};
    /// Axes in use: the evaluations skip the rest (zero), which the hot loops notice.
    std::size_t axes = kAxesMax;

    Vec point(double u) const {
        const double v = 1 - u;
        Vec r{};
        for (std::size_t i = 0; i < axes; ++i) {
            const double a = v * p[0][i] + u * p[1][i], b = v * p[1][i] + u * p[2][i],
                         c = v * p[2][i] + u * p[3][i];
            r[i] = v * (v * a + u * b) + u * (v * b + u * c);
        }
        return r;
    }
    Vec d1(double u) const {
        const double v = 1 - u;
        Vec r{};
        for (std::size_t i = 0; i < axes; ++i) {
            r[i] = 3 * (v * v * (p[1][i] - p[0][i]) + 2 * u * v * (p[2][i] - p[1][i]) +
                        u * u * (p[3][i] - p[2][i]));
        }
        return r;
    }
    Vec d2(double u) const {
        const double v = 1 - u;
        Vec r{};
        for (std::size_t i = 0; i < axes; ++i) {
            r[i] =
                6 * (v * (p[2][i] - 2 * p[1][i] + p[0][i]) + u * (p[3][i] - 2 * p[2][i] + p[1][i]));
        }
        return r;
    }
    /// Largest distance of a control point from P0: the segment's size.
    double size() const {
        double s = 0;
        for (std::size_t k = 1; k < 4; ++k) s = std::fmax(s, norm(sub(p[k], p[0])));
        return s;
    }
};

Cubic to_cubic(const BezierSegment& s);

/// |q'(u)|: the speed of `c`'s parameter.
double speed_at(const Cubic& c, double u);

/// Arc length of `c` over [u0, u1] by 5-point Gauss-Legendre quadrature of |q'(u)|.
double arc_length(const Cubic& c, double u0, double u1);

}  // namespace pathstream::host::planner_detail
