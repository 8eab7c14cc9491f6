#include "pathstream/forward_difference.hpp"

namespace pathstream {

template <typename Word>
Status start_differences(const TickCubic& cubic, const SpanTiming& timing, std::uint32_t k0,
                         DifferenceState<Word>& out) {
    if (k0 > timing.ticks) return Status::kTickOutsideSpan;
    const std::int64_t n = timing.ticks;
    const std::int64_t k = k0;
    const std::uint64_t den = timing.denominator;
    const Word bias = static_cast<Word>(difference_bias(timing));
    // D = 2^m: remainders kept as binary fractions of the word, r * 2^(W - m), with K = 0.
    // For D = 1 every remainder is 0 (and a shift by W would be undefined); m >= W only
    // breaks the precondition on Word.
    constexpr unsigned kWordBits = 8 * sizeof(Word);
    const auto m = static_cast<unsigned>(__builtin_ctzll(den));
    const unsigned binary_shift = is_binary(timing) && m > 0 && m < kWordBits ? kWordBits - m : 0;

    // The differences of Q at k: Delta1 = Q(k+1) - Q(k), Delta2, Delta3, expanded in k.
    const Int128 bn = Int128::from(cubic.b) * n;
    const Int128 a3 = Int128::from(3 * cubic.a);
    const Int128 a6 = Int128::from(6 * cubic.a);
    const Int128 delta1 =
        (a3 * k + a3 + bn + bn) * k + Int128::from(cubic.a) + bn + Int128::from(cubic.c) * (n * n);
    const Int128 delta2 = a6 * k + a6 + bn + bn;
    const Int128 level[4] = {tick_numerator(cubic, timing, k0) + Int128{den / 2, 0}, delta1, delta2,
                             a6};
    const Word level_bias[4] = {bias, 0, bias, 0};

    DifferenceState<Word> s{};
    for (int i = 0; i < 4; ++i) {
        const FloorDivision qr = floor_divide(level[i], den);
        const auto quotient = static_cast<std::uint32_t>(qr.quotient.lo);
        const auto remainder = static_cast<Word>(
            static_cast<Word>(static_cast<Word>(qr.remainder) << binary_shift) + level_bias[i]);
        if (i < 3) {
            s.quotient[i] = quotient;
            s.remainder[i] = remainder;
        } else {
            s.jerk_quotient = quotient;
            s.jerk_remainder = remainder;
        }
    }
    out = s;
    return Status::kOk;
}

template Status start_differences<std::uint32_t>(const TickCubic&, const SpanTiming&, std::uint32_t,
                                                 NarrowDifferences&);
template Status start_differences<std::uint64_t>(const TickCubic&, const SpanTiming&, std::uint32_t,
                                                 WideDifferences&);

}  // namespace pathstream
