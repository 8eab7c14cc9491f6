#include "pathstream/wide_int.hpp"

namespace pathstream {

Int128 multiply_portable(Int128 a, std::int64_t b) {
    const bool negate = a.negative() != (b < 0);
    const Int128 m = magnitude(a);
    const std::uint64_t bm =
        b < 0 ? 0 - static_cast<std::uint64_t>(b) : static_cast<std::uint64_t>(b);
    Int128 p = multiply_unsigned(m.lo, bm);
    p.hi += m.hi * bm;
    return negate ? -p : p;
}

Int128 operator*(Int128 a, std::int64_t b) {
#if defined(__SIZEOF_INT128__)
    // The same product modulo 2^128 in one native multiply where the target has one (the
    // host's planner runs every span's setup through here); Cortex-M takes the portable path.
    __extension__ using Native = unsigned __int128;
    const Native x = (static_cast<Native>(a.hi) << 64) | a.lo;
    const Native y = static_cast<Native>(Int128::from(b).hi) << 64 | Int128::from(b).lo;
    const Native p = x * y;
    return Int128{static_cast<std::uint64_t>(p), static_cast<std::uint64_t>(p >> 64)};
#else
    return multiply_portable(a, b);
#endif
}

FloorDivision floor_divide(Int128 a, std::uint64_t d) {
    const Int128 m = magnitude(a);
    Int128 q{};
    std::uint64_t r = 0;
    if (m.hi == 0) {
        q.lo = m.lo / d;
        r = m.lo % d;
    } else {
        // Long division, one bit at a time, of the 128-bit magnitude. The running remainder
        // stays below d < 2^64, so a 65th bit only appears transiently (tracked by carry).
        for (int bit = 127; bit >= 0; --bit) {
            const bool carry = (r >> 63) != 0;
            const std::uint64_t word = bit >= 64 ? m.hi : m.lo;
            r = (r << 1) | ((word >> (bit & 63)) & 1u);
            if (carry || r >= d) {
                r -= d;
                if (bit >= 64)
                    q.hi |= std::uint64_t{1} << (bit - 64);
                else
                    q.lo |= std::uint64_t{1} << bit;
            }
        }
    }
    if (!a.negative()) return FloorDivision{q, r};
    // floor(-m / d) = -(q + 1) with remainder d - r, unless the division was exact.
    if (r == 0) return FloorDivision{-q, 0};
    return FloorDivision{-(q + Int128::from(1)), d - r};
}

}  // namespace pathstream
