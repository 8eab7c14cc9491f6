// Two-word signed integer for the exact span arithmetic.
//
// Why not __int128: arm-none-eabi-g++ (32-bit targets) has no 128-bit integer type, and the
// core must compute bit-identical results on Cortex-M and on the host. Every operation here
// is portable C++ on 64-bit words; tests check it against the compiler's __int128 on x86-64.
// Used only at span setup and by the Horner evaluator, never by the per-tick loop.
#pragma once

#include <cstdint>

namespace pathstream {

/// Signed 128-bit integer in two's complement (value = hi * 2^64 + lo, hi carrying the sign).
/// Cost: a handful of 32/64-bit operations per add/compare; multiply is four 32x32 partials
/// per 64-bit limb. Plain value type, no state, safe in any context (task or interrupt).
struct Int128 {
    std::uint64_t lo = 0;
    std::uint64_t hi = 0;

    /// Sign-extends a 64-bit value.
    static constexpr Int128 from(std::int64_t v) {
        return Int128{static_cast<std::uint64_t>(v), v < 0 ? ~std::uint64_t{0} : 0};
    }
    constexpr bool negative() const { return (hi >> 63) != 0; }
    constexpr bool operator==(const Int128&) const = default;
};

constexpr Int128 operator+(Int128 a, Int128 b) {
    const std::uint64_t lo = a.lo + b.lo;
    return Int128{lo, a.hi + b.hi + (lo < a.lo ? 1u : 0u)};
}

constexpr Int128 operator-(Int128 a) {
    const std::uint64_t lo = ~a.lo + 1;
    return Int128{lo, ~a.hi + (lo == 0 ? 1u : 0u)};
}

constexpr Int128 operator-(Int128 a, Int128 b) {
    return a + (-b);
}

constexpr bool operator<(Int128 a, Int128 b) {
    const std::int64_t ah = static_cast<std::int64_t>(a.hi);
    const std::int64_t bh = static_cast<std::int64_t>(b.hi);
    return ah != bh ? ah < bh : a.lo < b.lo;
}
constexpr bool operator>(Int128 a, Int128 b) {
    return b < a;
}
constexpr bool operator<=(Int128 a, Int128 b) {
    return !(b < a);
}
constexpr bool operator>=(Int128 a, Int128 b) {
    return !(a < b);
}

/// |a| as an unsigned two-word magnitude. |INT128_MIN| wraps to itself, which callers never
/// reach: every value the core builds is bounded far below 2^126 at span setup.
constexpr Int128 magnitude(Int128 a) {
    return a.negative() ? -a : a;
}

/// Full 64x64 -> 128-bit unsigned product, from four 32x32 partial products.
constexpr Int128 multiply_unsigned(std::uint64_t a, std::uint64_t b) {
    const std::uint64_t a_lo = a & 0xFFFFFFFFu, a_hi = a >> 32;
    const std::uint64_t b_lo = b & 0xFFFFFFFFu, b_hi = b >> 32;
    const std::uint64_t ll = a_lo * b_lo, lh = a_lo * b_hi, hl = a_hi * b_lo, hh = a_hi * b_hi;
    const std::uint64_t middle = (ll >> 32) + (lh & 0xFFFFFFFFu) + (hl & 0xFFFFFFFFu);
    return Int128{(middle << 32) | (ll & 0xFFFFFFFFu),
                  hh + (lh >> 32) + (hl >> 32) + (middle >> 32)};
}

/// Signed 128 x signed 64 product, truncated to 128 bits. Exact whenever |a| * |b| < 2^127;
/// span setup bounds every operand so that it is (see docs/exact-math.md). Out of line:
/// setup code is called rarely and kept small.
Int128 operator*(Int128 a, std::int64_t b);

/// The same product from 64-bit words only: what operator* computes on targets without a
/// native 128-bit type (Cortex-M); on the host, the tests compare it with operator*.
Int128 multiply_portable(Int128 a, std::int64_t b);

/// Quotient and remainder of a floor division.
struct FloorDivision {
    Int128 quotient;
    std::uint64_t remainder = 0;  ///< in [0, divisor)
};

/// floor(a / d) and a - d * floor(a / d) for a divisor d > 0.
/// Cost: one 64-bit division when |a| < 2^64, otherwise a shift-subtract loop over 128 bits.
/// Setup and Horner only; out of line, one copy in the image.
FloorDivision floor_divide(Int128 a, std::uint64_t d);

}  // namespace pathstream
