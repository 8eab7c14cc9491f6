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
    return outward(a.lo + b.lo, a.hi + b.hi);
}

Interval operator-(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    return outward(a.lo - b.hi, a.hi - b.lo);
}

Interval operator-(const Interval& a) {
    return {-a.hi, -a.lo};
}

Interval operator*(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    const double p[] = {a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi};
    double lo = p[0], hi = p[0];
    for (const double v : p) {
        if (std::isnan(v)) return whole();
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    return outward(lo, hi);
}

Interval operator/(const Interval& a, const Interval& b) {
    if (a.undefined() || b.undefined()) return undefined();
    if (b.contains(0)) return whole();
    const double q[] = {a.lo / b.lo, a.lo / b.hi, a.hi / b.lo, a.hi / b.hi};
    double lo = q[0], hi = q[0];
    for (const double v : q) {
        if (std::isnan(v)) return whole();
        lo = std::min(lo, v);
        hi = std::max(hi, v);
    }
    return outward(lo, hi);
}

Interval sqr(const Interval& x) {
    if (x.undefined()) return undefined();
    const double small = mig(x), big = x.magnitude();
    return {std::max(0.0, down(small * small)), up(big * big)};
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
