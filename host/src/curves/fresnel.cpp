// Near 0 the power series cancels (its terms grow to about e^(πx²/2) before they shrink), so
// it is summed in double-double: at the switch to the asymptotic expansion the largest term is
// about 1e14 and double-double's 1e-32 still leaves 1e-18. The asymptotic expansion's smallest
// term at 4.7 is below 1e-16 and falls fast beyond.
#include "fresnel.hpp"

#include <cmath>
#include <limits>

namespace pathstream::host::curves {

namespace {

constexpr double kSwitch = 4.7;
// Past this f and g are below 1e-100: C and S are ±1/2 to every digit a double holds.
constexpr double kFar = 1e100;
// Bounds of |C| (its maximum is C(1)) and |S| (S(√2)), rounded up.
constexpr double kRange = 0.78;

struct DD {
    double hi = 0;
    double lo = 0;
};

DD two_sum(double a, double b) {
    const double s = a + b;
    const double bb = s - a;
    return {s, (a - (s - bb)) + (b - bb)};
}

DD two_prod(double a, double b) {
    const double p = a * b;
    return {p, std::fma(a, b, -p)};
}

DD add(DD a, DD b) {
    const DD s = two_sum(a.hi, b.hi);
    return two_sum(s.hi, s.lo + a.lo + b.lo);
}

DD mul(DD a, DD b) {
    const DD p = two_prod(a.hi, b.hi);
    return two_sum(p.hi, p.lo + a.hi * b.lo + a.lo * b.hi);
}

DD div(DD a, double b) {
    const double q = a.hi / b;
    const DD r = two_prod(q, b);
    return two_sum(q, (a.hi - r.hi - r.lo + a.lo) / b);
}

const DD kHalfPi{1.5707963267948966, 6.123233995736766e-17};
const DD kPiDD{3.141592653589793, 1.2246467991473532e-16};

// C and S of x >= 0 by the power series in z = πx²/2: z^k / k! / (2k + 1), even k to C and
// odd k to S, signs + + - - repeating.
void series(double x, double& c, double& s) {
    const DD z = mul(kHalfPi, two_prod(x, x));
    DD term{1, 0}, sum_c{0, 0}, sum_s{0, 0};
    for (int k = 0; k < 400; ++k) {
        if (k > 0) term = div(mul(term, z), k);
        DD part = div(term, 2.0 * k + 1);
        if (k % 4 >= 2) part = {-part.hi, -part.lo};
        if (k % 2 == 0) {
            sum_c = add(sum_c, part);
        } else {
            sum_s = add(sum_s, part);
        }
        if (k > z.hi && std::fabs(term.hi) < 1e-36) break;
    }
    c = x * sum_c.hi + x * sum_c.lo;
    s = x * sum_s.hi + x * sum_s.lo;
}

// sin and cos of πx²/2, with x²/2 reduced modulo 2 exactly first (the plain product loses all
// digits of the phase for large x).
void phase(double x, double& sine, double& cosine) {
    const DD w = two_prod(x, x);
    const DD half{w.hi / 2, w.lo / 2};
    // fmod is exact; both parts need it, as for large x the low part is a huge integer too.
    DD r = two_sum(std::fmod(half.hi, 2.0), std::fmod(half.lo, 2.0));
    const double even = 2 * std::nearbyint(r.hi / 2);
    r = two_sum(r.hi - even, r.lo);
    const DD theta = mul(kPiDD, r);
    sine = std::sin(theta.hi) + theta.lo * std::cos(theta.hi);
    cosine = std::cos(theta.hi) - theta.lo * std::sin(theta.hi);
}

// C and S of x >= kSwitch by the auxiliary functions f and g (DLMF 7.5.3-4, 7.12.2-3),
// summed until the terms stop shrinking.
void asymptotic(double x, double& c, double& s) {
    if (x > kFar) {
        c = s = 0.5;
        return;
    }
    const double y = M_PI * x * x;
    const double y2 = y * y;
    double f = 1, g = 1, a = 1, b = 1;
    for (int m = 1; m < 100; ++m) {
        const double next_a = -a * (4.0 * m - 3) * (4.0 * m - 1) / y2;
        const double next_b = -b * (4.0 * m - 1) * (4.0 * m + 1) / y2;
        if (std::fabs(next_a) >= std::fabs(a) || std::fabs(next_b) >= std::fabs(b)) break;
        a = next_a;
        b = next_b;
        f += a;
        g += b;
        if (std::fabs(a) < 1e-18 && std::fabs(b) < 1e-18) break;
    }
    f /= M_PI * x;
    g /= M_PI * M_PI * x * x * x;
    double sine = 0, cosine = 0;
    phase(x, sine, cosine);
    c = 0.5 + f * sine - g * cosine;
    s = 0.5 - f * cosine - g * sine;
}

void both(double x, double& c, double& s) {
    if (std::isnan(x)) {
        c = s = x;
        return;
    }
    const double ax = std::fabs(x);
    if (ax < kSwitch) {
        series(ax, c, s);
    } else {
        asymptotic(ax, c, s);
    }
    if (x < 0) {
        c = -c;
        s = -s;
    }
}

Interval enclose(const Interval& x, bool cosine) {
    if (x.undefined()) return undefined();
    const Interval range{-kRange, kRange};
    if (!x.bounded()) return range;
    const double m = x.lo + (x.hi - x.lo) / 2;
    const double at_m = cosine ? fresnel_c(m) : fresnel_s(m);
    const Interval arg = pi_interval() * sqr(x) / 2.0;
    const Interval slope = cosine ? cos(arg) : sin(arg);
    const Interval r =
        Interval(at_m - kFresnelMargin, at_m + kFresnelMargin) + slope * (x - Interval(m));
    return {std::fmax(r.lo, range.lo), std::fmin(r.hi, range.hi)};
}

}  // namespace

double fresnel_c(double x) {
    double c = 0, s = 0;
    both(x, c, s);
    return c;
}

double fresnel_s(double x) {
    double c = 0, s = 0;
    both(x, c, s);
    return s;
}

Interval fresnel_c(const Interval& x) {
    return enclose(x, true);
}

Interval fresnel_s(const Interval& x) {
    return enclose(x, false);
}

}  // namespace pathstream::host::curves
