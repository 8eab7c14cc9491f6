#include "pathstream/tick_cubic.hpp"

namespace pathstream {
namespace {

constexpr std::int64_t cube(std::int64_t n) {
    return n * n * n;
}

/// |v| <= limit * D, with v exact: the bound proofs compare numerators, never divide.
bool within(Int128 v, std::int64_t limit, std::uint64_t denominator) {
    const Int128 bound = Int128::from(limit) * static_cast<std::int64_t>(denominator);
    return magnitude(v) <= bound;
}

/// Largest magnitude among Bernstein-form values, each already scaled by `weight`.
bool all_within(const Int128* values, int count, std::int64_t limit, std::uint64_t denominator,
                std::int64_t weight) {
    for (int i = 0; i < count; ++i) {
        if (!within(values[i], limit * weight, denominator)) return false;
    }
    return true;
}

}  // namespace

Status make_span_timing(Basis basis, std::uint32_t ticks, SpanTiming& out) {
    if (!is_valid_basis(static_cast<std::uint8_t>(basis))) return Status::kUnknownBasis;
    if (ticks < 1 || ticks > kMaxSpanTicks) return Status::kTickCountOutOfRange;
    out.ticks = ticks;
    out.denominator = static_cast<std::uint64_t>(basis_matrix(basis).scale) *
                      static_cast<std::uint64_t>(cube(ticks));
    return Status::kOk;
}

Status make_tick_cubic(Basis basis, const std::int32_t (&control)[4], const SpanTiming& timing,
                       TickCubic& out) {
    if (!is_valid_basis(static_cast<std::uint8_t>(basis))) return Status::kUnknownBasis;
    if (timing.ticks < 1 || timing.ticks > kMaxSpanTicks) return Status::kTickCountOutOfRange;
    for (int i = 0; i < 4; ++i) {
        const bool tangent = basis == Basis::kHermite && i >= 2;
        const std::int64_t limit = tangent ? kMaxTangentLsb : kMaxPositionLsb;
        if (control[i] < -limit || control[i] > limit) return Status::kControlValueOutOfRange;
    }

    const BasisMatrix bm = basis_matrix(basis);
    std::int64_t coef[4] = {0, 0, 0, 0};
    for (int row = 0; row < 4; ++row) {
        for (int col = 0; col < 4; ++col) coef[row] += bm.m[row][col] * std::int64_t{control[col]};
    }
    const std::int64_t a = coef[0], b = coef[1], c = coef[2], d = coef[3];
    const std::int64_t n = timing.ticks;
    const std::uint64_t den = timing.denominator;

    // Curve: the Bernstein (Bezier) coefficients of a cubic bound it on [0, 1]. Times 3 they
    // are integers: 3d, 3d + c, 3d + 2c + b, 3(a + b + c + d); the curve is Q/D = value/scale.
    {
        const std::int64_t s = bm.scale;
        const std::int64_t hull[4] = {3 * d, 3 * d + c, 3 * d + 2 * c + b, 3 * (a + b + c + d)};
        for (std::int64_t h : hull) {
            const std::int64_t mag = h < 0 ? -h : h;
            if (mag > 3 * s * kMaxCurveLsb) return Status::kCurveOutOfRange;
        }
    }

    // Velocity per tick Delta1(k) = alpha k^2 + beta k + gamma on k in [0, n]; times 2 its
    // Bernstein coefficients are 2 gamma, 2 gamma + beta n, 2 gamma + 2 beta n + 2 alpha n^2.
    const Int128 bn = Int128::from(b) * n;
    const Int128 cnn = Int128::from(c) * (n * n);
    const Int128 alpha = Int128::from(3 * a);
    const Int128 beta = alpha + bn + bn;
    const Int128 gamma = Int128::from(a) + bn + cnn;
    {
        const Int128 two_gamma = gamma + gamma;
        const Int128 beta_n = beta * n;
        const Int128 v[3] = {two_gamma, two_gamma + beta_n,
                             two_gamma + beta_n + beta_n + (alpha + alpha) * (n * n)};
        if (!all_within(v, 3, kMaxDifferenceLsb, den, 2)) return Status::kDifferenceOutOfRange;
    }
    // Acceleration per tick Delta2(k) = 6a k + 6a + 2bn is linear: its ends bound it.
    {
        const Int128 at0 = Int128::from(6 * a) + bn + bn;
        const Int128 v[2] = {at0, at0 + Int128::from(6 * a) * n};
        if (!all_within(v, 2, kMaxDifferenceLsb, den, 1)) return Status::kDifferenceOutOfRange;
    }
    // Jerk per tick Delta3 = 6a is constant.
    {
        const Int128 v[1] = {Int128::from(6 * a)};
        if (!all_within(v, 1, kMaxDifferenceLsb, den, 1)) return Status::kDifferenceOutOfRange;
    }

    out = TickCubic{a, b, c, d};
    return Status::kOk;
}

Int128 tick_numerator(const TickCubic& cubic, const SpanTiming& timing, std::uint32_t k) {
    const std::int64_t n = timing.ticks;
    const std::int64_t kk = k;
    Int128 acc = Int128::from(cubic.a) * kk + Int128::from(cubic.b) * n;
    acc = acc * kk + Int128::from(cubic.c) * (n * n);
    acc = acc * kk + Int128::from(cubic.d) * (n * n) * n;
    return acc;
}

Status evaluate_at(const TickCubic& cubic, const SpanTiming& timing, std::uint32_t k, Lsb& out) {
    if (k > timing.ticks) return Status::kTickOutsideSpan;
    const Int128 half = Int128{timing.denominator / 2, 0};
    const FloorDivision q =
        floor_divide(tick_numerator(cubic, timing, k) + half, timing.denominator);
    out = static_cast<Lsb>(static_cast<std::int64_t>(q.quotient.lo));
    return Status::kOk;
}

}  // namespace pathstream
