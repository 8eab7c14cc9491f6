// Interval arithmetic with outward rounding: every result contains the exact result of the
// operation on every pair of reals drawn from the operands. This is what lets the curve fitter
// prove an error bound with floating-point arithmetic.
#pragma once

#include <cmath>
#include <limits>

namespace pathstream::host::curves {

/// A closed interval [lo, hi] of reals. Three kinds of value:
///  - bounded: both ends finite (lo <= hi);
///  - unbounded: an end is infinite (the whole line when nothing better is known, e.g. after a
///    division by an interval containing 0);
///  - undefined: an end is NaN (the function is not defined on part of the operand: sqrt or
///    ln of a negative part, asin outside [-1, 1]).
/// Callers that need a bound treat the last two alike: "cannot prove anything here".
struct Interval {
    double lo = 0;
    double hi = 0;

    Interval() = default;
    /// The point interval [x, x] (x is exact: a double converts without rounding).
    Interval(double x) : lo(x), hi(x) {}  // NOLINT: implicit, as a number is a point interval
    Interval(double low, double high) : lo(low), hi(high) {}

    /// Both ends finite (and not NaN).
    bool bounded() const { return std::isfinite(lo) && std::isfinite(hi); }
    bool undefined() const { return std::isnan(lo) || std::isnan(hi); }
    bool contains(double x) const { return lo <= x && x <= hi; }
    double width() const { return hi - lo; }
    /// The largest |x| over the interval (infinite when unbounded, NaN when undefined).
    double magnitude() const { return std::fmax(std::fabs(lo), std::fabs(hi)) + (lo - lo); }
};

/// The whole real line.
Interval whole();
/// The undefined interval (NaN ends).
Interval undefined();
/// The smallest interval holding both.
Interval hull(const Interval& a, const Interval& b);
/// An interval known to contain pi.
Interval pi_interval();
/// An interval known to contain e.
Interval e_interval();

// Arithmetic: each end is the nearest-rounded result stepped one ulp outward, which covers
// IEEE 754's correctly rounded operations. Results known exact stay exact: sums whose rounding
// error (two-sum) is 0 or of one sign step on that side only; products and quotients with a
// factor 0 or ±1 do not step. Each is O(1) and never throws; an undefined operand gives an
// undefined result, and inf - inf or 0 · inf the whole line.

/// Every a + b.
Interval operator+(const Interval& a, const Interval& b);
/// Every a - b.
Interval operator-(const Interval& a, const Interval& b);
/// Every -a (exact).
Interval operator-(const Interval& a);
/// Every a · b.
Interval operator*(const Interval& a, const Interval& b);
/// Every a / b; the whole line when b contains 0.
Interval operator/(const Interval& a, const Interval& b);
/// Every x², tighter than x * x when x contains 0 ([0, ...], never negative).
Interval sqr(const Interval& x);
/// Every x^n for an integer n (even n: never negative; negative n: the whole line when x
/// contains 0).
Interval integer_power(const Interval& x, int n);

// Elementary functions over an interval: each contains the function's value at every point of
// the operand. The C library's functions are assumed accurate to kLibmUlps ulps (glibc lists a
// few at most for these) and results are widened by that much at each end. Each is O(1) and
// never throws; undefined() where the operand reaches outside the domain.

/// The assumed accuracy of the C library's elementary functions, in ulps.
inline constexpr int kLibmUlps = 4;
/// Includes ±1 wherever the operand may contain a peak; [-1, 1] beyond |x| > 1e9.
Interval sin(const Interval& x);
/// As sin.
Interval cos(const Interval& x);
/// The whole line when x may contain a pole (pi/2 + k pi), is 3 or wider, or reaches past 1e9.
Interval tan(const Interval& x);
/// Undefined outside [-1, 1].
Interval asin(const Interval& x);
/// Undefined outside [-1, 1].
Interval acos(const Interval& x);
/// Monotone: the ends' values.
Interval atan(const Interval& x);
/// The angle of the points of the box y × x; [-pi, pi] when the box touches the origin or the
/// negative x axis (the branch cut).
Interval atan2(const Interval& y, const Interval& x);
/// Undefined when x has a negative part.
Interval sqrt(const Interval& x);
/// Never negative.
Interval exp(const Interval& x);
/// Natural logarithm; undefined when x has a negative part, -inf at the lower end for 0.
Interval log(const Interval& x);
/// As log.
Interval log10(const Interval& x);
/// Exact.
Interval fabs(const Interval& x);
/// Monotone: the ends' values.
Interval sinh(const Interval& x);
/// At least 1; its minimum at 0 when x contains 0.
Interval cosh(const Interval& x);
/// Within [-1, 1].
Interval tanh(const Interval& x);
/// Every min(a, b) (exact).
Interval fmin(const Interval& a, const Interval& b);
/// Every max(a, b) (exact).
Interval fmax(const Interval& a, const Interval& b);
/// Every sqrt(a² + b²).
Interval hypot(const Interval& a, const Interval& b);
/// Every a^b: integer_power when b is one integer point, else exp(b ln a) for a >= 0
/// (undefined where a has a negative part).
Interval pow(const Interval& a, const Interval& b);
/// The sign of x's points: [-1, 1] when x contains 0 (the slopes of |x| there).
Interval sign(const Interval& x);

}  // namespace pathstream::host::curves
