// The Fresnel integrals C(x) = ∫0^x cos(π s²/2) ds and S(x) = ∫0^x sin(π s²/2) ds (clothoids),
// as point values and as interval enclosures.
#pragma once

#include "interval.hpp"

namespace pathstream::host::curves {

/// The largest error fresnel_c and fresnel_s are trusted to have (the tests check them against
/// reference values at far smaller errors); the interval overloads widen by it.
inline constexpr double kFresnelMargin = 1e-14;

/// C(x), accurate to about 1e-16 absolute: a power series summed in double-double arithmetic
/// for |x| < 4.7, the auxiliary functions' asymptotic expansions beyond (with πx²/2 reduced
/// exactly before its sine and cosine). O(|x|² + 1) below 4.7, O(1) above; never throws.
/// NaN for NaN, ±0.5 for ±infinity.
double fresnel_c(double x);
/// S(x), as fresnel_c.
double fresnel_s(double x);

/// An interval containing C(x) for every x in `x`: the mean-value form C(m) + C'(X)(X - m)
/// with C' = cos(π x²/2) enclosed over X, widened by kFresnelMargin, and never wider than the
/// function's range. O(1); never throws; undefined for an undefined x.
Interval fresnel_c(const Interval& x);
/// An interval containing S(x) for every x in `x`, as fresnel_c.
Interval fresnel_s(const Interval& x);

}  // namespace pathstream::host::curves
