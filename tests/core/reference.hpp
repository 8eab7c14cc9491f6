// Independent exact reference for the core's spans, and seeded random span generators.
//
// Independent means: it uses the closed-form basis functions (Bernstein polynomials,
// B-spline blending functions, Catmull-Rom and Hermite weights) evaluated at u = k/n with the
// compiler's __int128, not the core's basis matrices, Int128 type or forward differences.
#pragma once

#include <cstdint>
#include <random>

#include "pathstream/basis.hpp"
#include "pathstream/units.hpp"

namespace pathstream::test {

using i128 = __int128;

/// Exact rational value of a span at tick k of n: numerator / denominator.
struct Rational {
    i128 numerator;
    i128 denominator;  ///< > 0
};

/// p(k/n) of one axis from the closed-form weights, exactly.
inline Rational reference_value(Basis basis, const std::int32_t (&p)[4], std::int64_t n,
                                std::int64_t k) {
    const i128 u = k, m = n - k, nn = n;
    i128 w[4] = {0, 0, 0, 0};
    i128 den = nn * nn * nn;
    switch (basis) {
        case Basis::kUniformBSpline:  // (1/6)[(1-u)^3, 3u^3-6u^2+4, -3u^3+3u^2+3u+1, u^3]
            den *= 6;
            w[0] = m * m * m;
            w[1] = 3 * u * u * u - 6 * u * u * nn + 4 * nn * nn * nn;
            w[2] = -3 * u * u * u + 3 * u * u * nn + 3 * u * nn * nn + nn * nn * nn;
            w[3] = u * u * u;
            break;
        case Basis::kCatmullRom:  // (1/2)[-u(1-u)^2, 3u^3-5u^2+2, -3u^3+4u^2+u, -u^2(1-u)]
            den *= 2;
            w[0] = -u * m * m;
            w[1] = 3 * u * u * u - 5 * u * u * nn + 2 * nn * nn * nn;
            w[2] = -3 * u * u * u + 4 * u * u * nn + u * nn * nn;
            w[3] = -u * u * m;
            break;
        case Basis::kBezier:  // Bernstein: (1-u)^3, 3u(1-u)^2, 3u^2(1-u), u^3
            w[0] = m * m * m;
            w[1] = 3 * u * m * m;
            w[2] = 3 * u * u * m;
            w[3] = u * u * u;
            break;
        case Basis::kHermite:  // h00, h01 on the points; h10, h11 on the tangents
            w[0] = 2 * u * u * u - 3 * u * u * nn + nn * nn * nn;
            w[1] = -2 * u * u * u + 3 * u * u * nn;
            w[2] = u * m * m;   // u^3 - 2u^2 + u = u (1-u)^2
            w[3] = -u * u * m;  // u^3 - u^2 = -u^2 (1-u)
            break;
    }
    i128 num = 0;
    for (int i = 0; i < 4; ++i) num += w[i] * p[i];
    return Rational{num, den};
}

/// floor(a / b) for b > 0.
inline i128 floor_div(i128 a, i128 b) {
    i128 q = a / b;
    if (a % b != 0 && a < 0) --q;
    return q;
}

/// The correctly rounded setpoint (halves toward +infinity): floor(x + 1/2).
inline std::int64_t reference_setpoint(Basis basis, const std::int32_t (&p)[4], std::int64_t n,
                                       std::int64_t k) {
    const Rational r = reference_value(basis, p, n, k);
    return static_cast<std::int64_t>(floor_div(2 * r.numerator + r.denominator, 2 * r.denominator));
}

/// Seeded generator of spans that cover the whole accepted range: tick counts log-uniform
/// over 1..65536 (so both narrow and wide spans), control values sometimes at the range
/// limits, sometimes small, sometimes clustered (gentle curves) around an offset.
class SpanGenerator {
public:
    explicit SpanGenerator(std::uint64_t seed) : rng_(seed) {}

    std::uint32_t ticks() {
        const int bits = static_cast<int>(rng_() % 17);  // 2^0 .. 2^16
        const std::uint64_t lo = std::uint64_t{1} << bits;
        const std::uint64_t hi = bits == 16 ? kMaxSpanTicks : (lo << 1) - 1;
        return static_cast<std::uint32_t>(lo + rng_() % (hi - lo + 1));
    }

    /// Four control values for `basis`, all within the input ranges.
    void control(Basis basis, std::int32_t (&p)[4]) {
        const int style = static_cast<int>(rng_() % 4);
        const std::int64_t center = uniform(-kMaxPositionLsb / 2, kMaxPositionLsb / 2);
        for (int i = 0; i < 4; ++i) {
            const bool tangent = basis == Basis::kHermite && i >= 2;
            const std::int64_t limit = tangent ? kMaxTangentLsb : kMaxPositionLsb;
            std::int64_t v = 0;
            switch (style) {
                case 0:
                    v = uniform(-limit, limit);
                    break;  // anywhere
                case 1:
                    v = (rng_() % 2 ? limit : -limit) - uniform(-3, 3);
                    break;  // at limits
                case 2:
                    v = uniform(-1000, 1000);
                    break;  // tiny
                default:
                    v = center + uniform(-50000, 50000);
                    break;  // gentle
            }
            if (tangent && style == 3) v = uniform(-200000, 200000);
            if (v > limit) v = limit;
            if (v < -limit) v = -limit;
            p[i] = static_cast<std::int32_t>(v);
        }
    }

    Basis basis() { return static_cast<Basis>(rng_() % kBasisCount); }
    std::int64_t uniform(std::int64_t lo, std::int64_t hi) {
        return lo + static_cast<std::int64_t>(rng_() % static_cast<std::uint64_t>(hi - lo + 1));
    }
    std::mt19937_64& engine() { return rng_; }

private:
    std::mt19937_64 rng_;
};

}  // namespace pathstream::test
