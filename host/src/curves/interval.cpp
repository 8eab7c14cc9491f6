// Outward rounding by stepping to the next double: simpler than switching the rounding mode,
// and safe under any optimisation level (which may move operations across a mode switch).
#include "interval.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <initializer_list>

namespace pathstream::host::curves {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kPi = 3.141592653589793;
// Past this the argument reduction of sin/cos/tan in k units is too coarse to trust.
constexpr double kPeriodicLimit = 1e9;
constexpr std::uint64_t kInfBits = 0x7ff0000000000000;

// The next double toward -infinity: std::nextafter's result without its call (a fit makes
// tens of millions of these), by stepping the bit pattern.
double next_down(double x) {
    if (std::isnan(x) || x == -kInf) return x;
    if (x == 0) return -std::numeric_limits<double>::denorm_min();
    const auto bits = std::bit_cast<std::uint64_t>(x);
    return std::bit_cast<double>(x > 0 ? bits - 1 : bits + 1);
}

double down(double x, int ulps = 1) {
    // Finite and at least `ulps` steps away from 0 and infinity: one integer step.
    const auto bits = std::bit_cast<std::uint64_t>(x);
    const auto magnitude = bits & ~(std::uint64_t{1} << 63);
    const auto steps = static_cast<std::uint64_t>(ulps);
    if (x > 0 && magnitude < kInfBits && magnitude > steps)
        return std::bit_cast<double>(bits - steps);
    if (x < 0 && magnitude + steps < kInfBits) return std::bit_cast<double>(bits + steps);
    for (int i = 0; i < ulps; ++i) x = next_down(x);
    return x;
}

double up(double x, int ulps = 1) {
    return -down(-x, ulps);
}

// [lo, hi] widened; a NaN end from inf - inf or 0 * inf means "anything": the whole line.
Interval outward(double lo, double hi, int ulps = 1) {
    if (std::isnan(lo) || std::isnan(hi)) return whole();
    return {down(lo, ulps), up(hi, ulps)};
}

// Bounds of the exact a + b: the rounded sum, stepped outward only on the side where the exact
// error (two-sum, exact for every finite pair) says the exact sum lies. Exact sums stay points,
// which also keeps sums with 0 from stepping into subnormals (slow on most CPUs).
Interval sum_bounds(double a, double b) {
    const double s = a + b;
    if (!std::isfinite(s)) return {down(s), up(s)};
    const double bb = s - a;
    const double error = (a - (s - bb)) + (b - bb);
    return {error < 0 ? down(s) : s, error > 0 ? up(s) : s};
}

// Bounds of the exact a · b: one step each way, except where the product is exact (a factor 0
// or ±1). The step on both sides costs less than finding the error's sign by fma, which is a
// library call on CPUs without it.
Interval product_bounds(double a, double b) {
    const double p = a * b;
    if (a == 0 || b == 0 || std::fabs(a) == 1 || std::fabs(b) == 1) return {p, p};
    return {down(p), up(p)};
}

// Bounds of the exact a / b (b != 0), as product_bounds.
Interval quotient_bounds(double a, double b) {
    const double q = a / b;
    if (a == 0 || std::fabs(b) == 1) return {q, q};
    return {down(q), up(q)};
}

// [lo, hi] from bounds already rounded outward; NaN (inf - inf, 0 · inf among `parts`) means
// "anything": the whole line.
Interval checked(double lo, double hi, const Interval* parts = nullptr) {
    if (parts != nullptr) {
        for (int i = 0; i < 4; ++i) {
            if (std::isnan(parts[i].lo) || std::isnan(parts[i].hi)) return whole();
        }
    }
    if (std::isnan(lo) || std::isnan(hi)) return whole();
    return {lo, hi};
}

Interval libm(double lo, double hi) {
    return outward(lo, hi, kLibmUlps);
}

Interval clamp(Interval x, double lo, double hi) {
    return {std::max(x.lo, lo), std::min(x.hi, hi)};
}

// Mignitude: the smallest |x| over the interval.
double mig(const Interval& x) {
    if (x.contains(0)) return 0;
    return std::min(std::fabs(x.lo), std::fabs(x.hi));
}

// sin (offset pi/2) or cos (offset 0): extremes at offset + k pi, of value (-1)^k. A k near
// either end is taken as inside, which only widens the result.
Interval periodic(const Interval& x, double (*f)(double), double offset) {
    if (x.undefined()) return undefined();
    const Interval unit{-1, 1};
    if (!x.bounded() || x.width() > 7 || x.magnitude() > kPeriodicLimit) return unit;
    Interval r = libm(std::min(f(x.lo), f(x.hi)), std::max(f(x.lo), f(x.hi)));
    constexpr double kSlack = 1e-6;
    const double first = std::ceil((x.lo - offset) / kPi - kSlack);
    const double last = std::floor((x.hi - offset) / kPi + kSlack);
    for (double k = first; k <= last; k += 1) {
        if (std::fmod(k, 2.0) == 0) {
            r.hi = 1;
        } else {
            r.lo = -1;
        }
    }
    return clamp(r, -1, 1);
}

}  // namespace

Interval whole() {
    return {-kInf, kInf};
}

Interval undefined() {
    return {kNaN, kNaN};
}

Interval hull(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    return {std::min(a.lo, b.lo), std::max(a.hi, b.hi)};
}

Interval pi_interval() {
    return {down(kPi), up(kPi)};
}

Interval e_interval() {
    return {down(2.718281828459045), up(2.718281828459045)};
}

Interval operator+(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    return checked(sum_bounds(a.lo, b.lo).lo, sum_bounds(a.hi, b.hi).hi);
}

Interval operator-(const Interval& a, const Interval& b) {
    return a + -b;
}

Interval operator-(const Interval& a) {
    return {-a.hi, -a.lo};
}

Interval operator*(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    const Interval p[] = {product_bounds(a.lo, b.lo), product_bounds(a.lo, b.hi),
                          product_bounds(a.hi, b.lo), product_bounds(a.hi, b.hi)};
    return checked(std::min({p[0].lo, p[1].lo, p[2].lo, p[3].lo}),
                   std::max({p[0].hi, p[1].hi, p[2].hi, p[3].hi}), p);
}

Interval operator/(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    if (b.contains(0)) return whole();
    const Interval q[] = {quotient_bounds(a.lo, b.lo), quotient_bounds(a.lo, b.hi),
                          quotient_bounds(a.hi, b.lo), quotient_bounds(a.hi, b.hi)};
    return checked(std::min({q[0].lo, q[1].lo, q[2].lo, q[3].lo}),
                   std::max({q[0].hi, q[1].hi, q[2].hi, q[3].hi}), q);
}

Interval sqr(const Interval& x) {
    if (x.undefined()) return undefined();
    const double small = mig(x), big = x.magnitude();
    return {std::max(0.0, product_bounds(small, small).lo), product_bounds(big, big).hi};
}

Interval integer_power(const Interval& x, int n) {
    if (x.undefined()) return undefined();
    if (n == 0) return 1.0;
    if (n < 0) return Interval(1.0) / integer_power(x, -n);
    if (n % 2 == 0) {
        const Interval r = libm(std::pow(mig(x), n), std::pow(x.magnitude(), n));
        return {std::max(0.0, r.lo), r.hi};
    }
    return libm(std::pow(x.lo, n), std::pow(x.hi, n));
}

Interval sin(const Interval& x) {
    return periodic(
        x, [](double v) { return std::sin(v); }, kPi / 2);
}

Interval cos(const Interval& x) {
    return periodic(
        x, [](double v) { return std::cos(v); }, 0);
}

Interval tan(const Interval& x) {
    if (x.undefined()) return undefined();
    if (!x.bounded() || x.width() >= 3 || x.magnitude() > kPeriodicLimit) return whole();
    constexpr double kSlack = 1e-6;
    const double first = std::ceil((x.lo - kPi / 2) / kPi - kSlack);
    const double last = std::floor((x.hi - kPi / 2) / kPi + kSlack);
    if (first <= last) return whole();
    return libm(std::tan(x.lo), std::tan(x.hi));
}

Interval asin(const Interval& x) {
    if (x.undefined() || x.lo < -1 || x.hi > 1) return undefined();
    return libm(std::asin(x.lo), std::asin(x.hi));
}

Interval acos(const Interval& x) {
    if (x.undefined() || x.lo < -1 || x.hi > 1) return undefined();
    return libm(std::acos(x.hi), std::acos(x.lo));
}

Interval atan(const Interval& x) {
    if (x.undefined()) return undefined();
    return libm(std::atan(x.lo), std::atan(x.hi));
}

Interval atan2(const Interval& y, const Interval& x) {
    if (y.undefined() || x.undefined()) return undefined();
    const Interval all{-up(kPi), up(kPi)};
    if (!x.bounded() || !y.bounded() || (x.lo <= 0 && y.contains(0))) return all;
    // The box misses the origin and the cut: its angles form one arc, ended by two corners.
    double lo = kInf, hi = -kInf;
    for (const double yy : {y.lo, y.hi}) {
        for (const double xx : {x.lo, x.hi}) {
            lo = std::min(lo, std::atan2(yy, xx));
            hi = std::max(hi, std::atan2(yy, xx));
        }
    }
    return clamp(libm(lo, hi), all.lo, all.hi);
}

Interval sqrt(const Interval& x) {
    if (x.undefined() || x.lo < 0) return undefined();
    return {std::max(0.0, down(std::sqrt(x.lo))), up(std::sqrt(x.hi))};
}

Interval exp(const Interval& x) {
    if (x.undefined()) return undefined();
    const Interval r = libm(std::exp(x.lo), std::exp(x.hi));
    return {std::max(0.0, r.lo), r.hi};
}

Interval log(const Interval& x) {
    if (x.undefined() || x.lo < 0) return undefined();
    return libm(std::log(x.lo), std::log(x.hi));
}

Interval log10(const Interval& x) {
    if (x.undefined() || x.lo < 0) return undefined();
    return libm(std::log10(x.lo), std::log10(x.hi));
}

Interval fabs(const Interval& x) {
    if (x.undefined()) return undefined();
    return {mig(x), x.magnitude()};
}

Interval sinh(const Interval& x) {
    if (x.undefined()) return undefined();
    return libm(std::sinh(x.lo), std::sinh(x.hi));
}

Interval cosh(const Interval& x) {
    if (x.undefined()) return undefined();
    const Interval r = libm(std::cosh(mig(x)), std::cosh(x.magnitude()));
    return {std::max(1.0, r.lo), r.hi};
}

Interval tanh(const Interval& x) {
    if (x.undefined()) return undefined();
    return clamp(libm(std::tanh(x.lo), std::tanh(x.hi)), -1, 1);
}

Interval fmin(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    return {std::min(a.lo, b.lo), std::min(a.hi, b.hi)};
}

Interval fmax(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    return {std::max(a.lo, b.lo), std::max(a.hi, b.hi)};
}

Interval hypot(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    const Interval r = libm(std::hypot(mig(a), mig(b)), std::hypot(a.magnitude(), b.magnitude()));
    return {std::max(0.0, r.lo), r.hi};
}

Interval pow(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    if (b.lo == b.hi && std::fabs(b.lo) <= 1 << 30 && std::trunc(b.lo) == b.lo)
        return integer_power(a, static_cast<int>(b.lo));
    if (a.lo < 0) return undefined();
    return exp(b * log(a));
}

Interval sign(const Interval& x) {
    if (x.undefined()) return undefined();
    if (x.lo > 0) return 1.0;
    if (x.hi < 0) return -1.0;
    return {-1, 1};
}

}  // namespace pathstream::host::curves
