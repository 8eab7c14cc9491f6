// Exact forward differencing of a tick cubic with no division per tick.
//
// Each difference level i (0: position, 1: velocity, 2: acceleration, 3: jerk, all per tick)
// is kept as a quotient q_i and a remainder r_i in [0, D): value_i = q_i + r_i / D. One tick
// adds level i+1 into level i for i = 0, 1, 2: add the remainders, carry into the quotient.
// Level 0 starts offset by floor(D/2), so q_0 is round(Q(k)/D) at every tick, exactly.
//
// The carry costs no compare: remainders are stored biased, level i by B_i with
// B_0 = B_2 = K, B_1 = B_3 = 0 and K = 2^W - D (W = 32 or 64 bits). Then adding the stored
// words of levels i and i+1 gives r_i + r_{i+1} + K, which overflows the word exactly when
// r_i + r_{i+1} >= D; the hardware carry is the quotient's carry, and one conditional add
// or subtract of K restores the bias (details and proof: docs/exact-math.md).
// W = 32 when D < 2^32 ("narrow" spans: n <= 894 for B-splines, 1290 for Catmull-Rom,
// 1625 for Bezier/Hermite), else W = 64.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "pathstream/units.hpp"

namespace pathstream {

#if defined(__x86_64__) && !defined(PATHSTREAM_PORTABLE_STEP)
// One tick of one axis on x86-64 with the state in registers. Per level: LEA computes the
// corrected sum (it leaves the flags alone), ADD sets the carry flag exactly when the
// remainder wraps (the biasing above), CMOV picks the corrected or the plain sum, and ADC
// adds the quotients and the carry: 14 instructions, no branch. GCC 12 compiles the C++
// select to data-dependent jumps and the mask to SETC/NEG/AND chains, about twice as long.
// Operands: r0..r2 and q0..q2 the changing levels (read and written), t scratch (early
// clobber), k = K, jr and jq the jerk level, jrk = jr + K.
#define PATHSTREAM_X86_STEP_ASM       \
    "lea (%q[r0],%q[r1]), %q[t]\n\t"  \
    "add %[k], %[t]\n\t"              \
    "add %[r1], %[r0]\n\t"            \
    "cmovc %[t], %[r0]\n\t"           \
    "adc %[q1], %[q0]\n\t"            \
    "lea (%q[r1],%q[r2]), %q[t]\n\t"  \
    "sub %[k], %[t]\n\t"              \
    "add %[r2], %[r1]\n\t"            \
    "cmovnc %[t], %[r1]\n\t"          \
    "adc %[q2], %[q1]\n\t"            \
    "lea (%q[r2],%q[jrk]), %q[t]\n\t" \
    "add %[jr], %[r2]\n\t"            \
    "cmovc %[t], %[r2]\n\t"           \
    "adc %[jq], %[q2]"
#define PATHSTREAM_X86_STEP_OUTPUTS                                                           \
    [r0] "+r"(r0), [r1] "+r"(r1), [r2] "+r"(r2), [q0] "+r"(q0), [q1] "+r"(q1), [q2] "+r"(q2), \
        [t] "=&r"(t)
#define PATHSTREAM_X86_STEP_INPUTS [k] "r"(bias), [jr] "r"(jr), [jrk] "r"(jrk), [jq] "r"(jq)
#endif

/// Forward-differencing state of one axis with W-bit remainders (Word = uint32_t or uint64_t).
/// The constant jerk level comes first and the three changing levels after it, so that on
/// Thumb-2 one LDMIA loads a narrow state and one STMDB stores the changed part back.
template <typename Word>
struct DifferenceState {
    Word jerk_remainder;          ///< level 3 remainder (bias 0), constant in a span
    std::uint32_t jerk_quotient;  ///< level 3 quotient, constant in a span
    Word remainder[3];            ///< levels 0..2, biased by K, 0, K
    std::uint32_t quotient[3];    ///< levels 0..2 as two's complement int32

    /// Current setpoint: the exact curve at the current tick, rounded once.
    constexpr Lsb position() const { return static_cast<Lsb>(quotient[0]); }

    /// Advances one tick. `bias` is K = 2^W - D of the span.
    /// Three spellings of the same arithmetic, chosen for what each compiler makes of them:
    /// on ARM a carry-select (GCC emits IT blocks on Thumb-2 and one short forward branch per
    /// level on ARMv6-M, half the instructions of mask arithmetic there); on x86-64 inline
    /// assembly (ADD, ADC, CMOV per level), because x86 compilers turn the select into
    /// data-dependent jumps that mispredict; elsewhere, or with PATHSTREAM_PORTABLE_STEP, an
    /// all-zeros/all-ones mask in C++. Both builds are cross-checked by the Cortex-M checksum
    /// tests; the x86-64 and the mask spellings by core_tests and core_tests_portable_step.
    /// Interrupt-safe: touches only this object.
    constexpr void step(Word bias) {
#if defined(__arm__)
        // Level by level, in place: few values live at once (ARMv6-M has eight low registers).
        // Level i reads level i+1 before level i+1 is updated, as the recurrence requires.
        Word sum;
        bool carry = __builtin_add_overflow(remainder[0], remainder[1], &sum);
        quotient[0] += quotient[1] + (carry ? 1u : 0u);
        remainder[0] = carry ? static_cast<Word>(sum + bias) : sum;
        carry = __builtin_add_overflow(remainder[1], remainder[2], &sum);
        quotient[1] += quotient[2] + (carry ? 1u : 0u);
        remainder[1] = carry ? sum : static_cast<Word>(sum - bias);
        carry = __builtin_add_overflow(remainder[2], jerk_remainder, &sum);
        quotient[2] += jerk_quotient + (carry ? 1u : 0u);
        remainder[2] = carry ? static_cast<Word>(sum + bias) : sum;
#elif defined(__x86_64__) && !defined(PATHSTREAM_PORTABLE_STEP)
        Word r0 = remainder[0], r1 = remainder[1], r2 = remainder[2], t;
        std::uint32_t q0 = quotient[0], q1 = quotient[1], q2 = quotient[2];
        const Word jr = jerk_remainder, jrk = static_cast<Word>(jr + bias);
        const std::uint32_t jq = jerk_quotient;
        // clang-format off
        __asm__(PATHSTREAM_X86_STEP_ASM
                : PATHSTREAM_X86_STEP_OUTPUTS
                : PATHSTREAM_X86_STEP_INPUTS
                : "cc");
        // clang-format on
        remainder[0] = r0;
        remainder[1] = r1;
        remainder[2] = r2;
        quotient[0] = q0;
        quotient[1] = q1;
        quotient[2] = q2;
#else
        const Word r0 = remainder[0], r1 = remainder[1], r2 = remainder[2];
        Word sum0, sum1, sum2;
        const bool c0 = __builtin_add_overflow(r0, r1, &sum0);
        const bool c1 = __builtin_add_overflow(r1, r2, &sum1);
        const bool c2 = __builtin_add_overflow(r2, jerk_remainder, &sum2);
        quotient[0] += quotient[1] + (c0 ? 1u : 0u);
        quotient[1] += quotient[2] + (c1 ? 1u : 0u);
        quotient[2] += jerk_quotient + (c2 ? 1u : 0u);
        const Word m0 = 0 - static_cast<Word>(c0), m2 = 0 - static_cast<Word>(c2);
        const Word keep1 = static_cast<Word>(c1) - 1;  // all ones when there was no carry
        remainder[0] = static_cast<Word>(sum0 + (bias & m0));
        remainder[1] = static_cast<Word>(sum1 - (bias & keep1));
        remainder[2] = static_cast<Word>(sum2 + (bias & m2));
#endif
    }
};

using NarrowDifferences = DifferenceState<std::uint32_t>;
using WideDifferences = DifferenceState<std::uint64_t>;

/// Writes each axis's current setpoint to `out`, then advances every axis one tick: the
/// per-axis work of one tick in C++. The tick interrupt's narrow spans go through
/// narrow_tick (narrow_tick.hpp), which is this plus the span's countdown and, on Cortex-M,
/// assembly. Interrupt-safe: touches only `state` and `out`.
template <unsigned Axes, typename Word>
inline void emit_and_step(DifferenceState<Word> (&state)[Axes], Lsb (&out)[Axes], Word bias) {
#if defined(__arm__)
    if constexpr (sizeof(Word) == 4) {
        // Unrolled (GCC keeps the loop otherwise): the setpoint is stored before the step, so
        // aliasing costs nothing, and the constant jerk level is never written back.
#pragma GCC unroll 8
        for (unsigned a = 0; a < Axes; ++a) {
            out[a] = state[a].position();
            state[a].step(bias);
        }
        return;
    }
#endif
    for (unsigned a = 0; a < Axes; ++a) {
#if defined(__arm__)
        // In place: the setpoint is stored before the step, so aliasing costs nothing, and
        // the constant jerk level is never written back (a copy would store all eight words).
        out[a] = state[a].position();
        state[a].step(bias);
#elif defined(__x86_64__) && !defined(PATHSTREAM_PORTABLE_STEP)
        // Loads first, then the setpoint (`out` may alias the quotients), then the step with
        // its six stores inside the assembly: stored from C++, GCC packs four of them into one
        // vector store, which the next tick's 4- and 8-byte loads cannot forward from. The
        // stores address the state through one register, so that a build at -O0 (where each
        // memory operand would take a register of its own) has registers enough.
        DifferenceState<Word>& s = state[a];
        Word r0 = s.remainder[0], r1 = s.remainder[1], r2 = s.remainder[2], t;
        std::uint32_t q0 = s.quotient[0], q1 = s.quotient[1], q2 = s.quotient[2];
        const Word jr = s.jerk_remainder, jrk = static_cast<Word>(jr + bias);
        const std::uint32_t jq = s.jerk_quotient;
        out[a] = static_cast<Lsb>(q0);
        __asm__(PATHSTREAM_X86_STEP_ASM
                "\n\tmov %[r0], %c[rem](%[p])"
                "\n\tmov %[r1], %c[rem]+%c[w](%[p])"
                "\n\tmov %[r2], %c[rem]+2*%c[w](%[p])"
                "\n\tmov %[q0], %c[quo](%[p])"
                "\n\tmov %[q1], %c[quo]+4(%[p])"
                "\n\tmov %[q2], %c[quo]+8(%[p])"
                : PATHSTREAM_X86_STEP_OUTPUTS, "+m"(s)
                : PATHSTREAM_X86_STEP_INPUTS, [p] "r"(&s),
                  [rem] "i"(offsetof(DifferenceState<Word>, remainder)),
                  [quo] "i"(offsetof(DifferenceState<Word>, quotient)), [w] "i"(sizeof(Word))
                : "cc");
#else
        // A local copy: `out` (int32) may alias the quotients (uint32) as far as the compiler
        // knows, which would otherwise force every field through memory on x86.
        DifferenceState<Word> s = state[a];
        out[a] = s.position();
        s.step(bias);
        state[a] = s;
#endif
    }
}

/// Writes the setpoints of `count` consecutive ticks to out[0..count) (out[t][a]: tick t,
/// axis a) and advances every axis `count` ticks: the same setpoints and the same final
/// state as `count` calls of emit_and_step. For code that wants many ticks at once (a host
/// simulator, a batch fill): each axis's state stays in registers for all its ticks instead
/// of being loaded and stored every tick, which on x86-64 about doubles the rate (bench_eval).
/// Requires `count` <= the ticks left in the span (the end point may be reached, not
/// passed). Cost: one step and one store per axis per tick, one state copy per axis per
/// call; no allocation. Any context, though the tick interrupt, which produces one tick at a
/// time, uses emit_and_step. Touches only `state` and out[0..count).
template <unsigned Axes, typename Word>
inline void emit_span_ticks(DifferenceState<Word> (&state)[Axes], Lsb (*out)[Axes],
                            std::uint32_t count, Word bias) {
    for (unsigned a = 0; a < Axes; ++a) {
        // A copy nothing else can see, so the compiler keeps every field in a register
        // across the ticks; axis by axis, so the fields of one axis fit the register file.
        DifferenceState<Word> s = state[a];
        for (std::uint32_t t = 0; t < count; ++t) {
            out[t][a] = s.position();
            s.step(bias);
        }
        state[a] = s;
    }
}

/// True when a span with this timing uses 32-bit remainders.
constexpr bool is_narrow(const SpanTiming& timing) {
    return timing.denominator < (std::uint64_t{1} << 32);
}

/// True when D is a power of two: Hermite and Bezier spans of 2^j ticks, Catmull-Rom spans of
/// 2^j ticks. Their remainders are kept as binary fractions of the word (r * 2^W / D), so the
/// word's carry is the mixed-radix carry with no bias at all (K = 0, docs/exact-math.md).
constexpr bool is_binary(const SpanTiming& timing) {
    return (timing.denominator & (timing.denominator - 1)) == 0;
}

/// K = 2^W - D for the word width the span uses (returned in 64 bits for both widths), or 0
/// when D is a power of two (is_binary).
constexpr std::uint64_t difference_bias(const SpanTiming& timing) {
    if (is_binary(timing)) return 0;
    return is_narrow(timing) ? (std::uint64_t{1} << 32) - timing.denominator
                             : 0 - timing.denominator;
}

/// Sets `out` to the state at tick k0 of the span (0 <= k0 <= ticks). Requires a cubic built
/// by make_tick_cubic with this timing (its bounds keep every quotient in int32), and Word
/// wide enough for D (uint32_t only when is_narrow). Cost: four 128/64 floor divisions and a
/// dozen 128-bit multiplies. Task context.
template <typename Word>
[[nodiscard]] Status start_differences(const TickCubic& cubic, const SpanTiming& timing,
                                       std::uint32_t k0, DifferenceState<Word>& out);

extern template Status start_differences<std::uint32_t>(const TickCubic&, const SpanTiming&,
                                                        std::uint32_t, NarrowDifferences&);
extern template Status start_differences<std::uint64_t>(const TickCubic&, const SpanTiming&,
                                                        std::uint32_t, WideDifferences&);

}  // namespace pathstream

#if defined(PATHSTREAM_X86_STEP_ASM)
#undef PATHSTREAM_X86_STEP_ASM
#undef PATHSTREAM_X86_STEP_OUTPUTS
#undef PATHSTREAM_X86_STEP_INPUTS
#endif
