// One tick of a narrow span on every axis: the tick interrupt's whole per-axis work.
//
// C++ everywhere; Thumb-2 assembly on Cortex-M3/M4/M7 and Thumb-1 assembly on ARMv6-M
// (Cortex-M0/M0+), because GCC spends half again to twice the instructions on the C++ there
// (docs/cortex-m.md). All spellings run the same arithmetic (docs/exact-math.md) and are
// cross-checked bit for bit against the host by the Cortex-M checksum tests. Define
// PATHSTREAM_PORTABLE_STEP to use the C++ on ARM as well. The assembly never touches r7, the
// Thumb frame pointer, so it builds at -O0 and with -fno-omit-frame-pointer too.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/forward_difference.hpp"
#include "pathstream/span.hpp"
#include "pathstream/units.hpp"

// clang-format off: assembly text, laid out by hand.
#if defined(__arm__) && defined(__thumb__) && !defined(PATHSTREAM_PORTABLE_STEP)
#define PATHSTREAM_ARM_TICK_ASM 1
// The assembly is one statement per tick with its per-axis text repeated by the preprocessor,
// not by .rept: GCC sizes an asm statement by its lines, and its own branches around a
// statement that expands later can fall short.
#define PATHSTREAM_REPEAT_0(X)
#define PATHSTREAM_REPEAT_1(X) X
#define PATHSTREAM_REPEAT_2(X) X X
#define PATHSTREAM_REPEAT_3(X) X X X
#define PATHSTREAM_REPEAT_4(X) X X X X
#define PATHSTREAM_REPEAT_5(X) X X X X X
#define PATHSTREAM_REPEAT_6(X) X X X X X X
#define PATHSTREAM_REPEAT_7(X) X X X X X X X
#define PATHSTREAM_REPEAT_8(X) X X X X X X X X
// STATEMENT(REPEAT) with REPEAT = PATHSTREAM_REPEAT_<Axes - SKIP>.
#define PATHSTREAM_FOR_AXES(STATEMENT, SKIP)            \
    if constexpr (Axes - SKIP == 0) {                   \
        STATEMENT(PATHSTREAM_REPEAT_0);                 \
    } else if constexpr (Axes - SKIP == 1) {            \
        STATEMENT(PATHSTREAM_REPEAT_1);                 \
    } else if constexpr (Axes - SKIP == 2) {            \
        STATEMENT(PATHSTREAM_REPEAT_2);                 \
    } else if constexpr (Axes - SKIP == 3) {            \
        STATEMENT(PATHSTREAM_REPEAT_3);                 \
    } else if constexpr (Axes - SKIP == 4) {            \
        STATEMENT(PATHSTREAM_REPEAT_4);                 \
    } else if constexpr (Axes - SKIP == 5) {            \
        STATEMENT(PATHSTREAM_REPEAT_5);                 \
    } else if constexpr (Axes - SKIP == 6) {            \
        STATEMENT(PATHSTREAM_REPEAT_6);                 \
    } else if constexpr (Axes - SKIP == 7) {            \
        STATEMENT(PATHSTREAM_REPEAT_7);                 \
    } else {                                            \
        static_assert(Axes - SKIP == 8, "1 to 8 axes"); \
        STATEMENT(PATHSTREAM_REPEAT_8);                 \
    }
#endif

#if defined(PATHSTREAM_ARM_TICK_ASM) && defined(__thumb2__)
// The Thumb-2 tick is an asm goto whose outputs must hold on its jumps to labels as well: GCC
// 11 on, clang 16 on. Other compilers take the C++ step.
#if defined(__clang__)
#if __has_extension(gnu_asm_goto_with_outputs_full)
#define PATHSTREAM_T2_TICK_ASM 1
#endif
#elif __GNUC__ >= 11
#define PATHSTREAM_T2_TICK_ASM 1
#endif
// Thumb-2: the whole tick of a narrow span, in narrow_tick_fast, addressed from the stream's
// tick state at `this` (NarrowTick). One LDMIA brings K (r3), the countdown (r4) and axis 0:
// jerk remainder and quotient (r5, r6), remainders 0..2 (r8..r10), quotients 0..2 (r11, r12,
// lr); one STMDB writes the countdown and the state back. Each further axis is one LDMIA of
// its eight words and one STMDB of the six that change. Per level: ADDS (the carry), ADC (the
// quotient) and, unless binary, the correction by K in an IT block: levels 0 and 2 are stored
// biased by K (add K after a carry), level 1 unbiased (subtract K when there was none).
//
// Between the LDMIA and the steps, one SUBS of the countdown and one conditional branch: a
// general span with ticks left after this one goes to its step (label 8, last in the
// statement, so that its end is the statement's fall-through). Otherwise (the countdown's
// encoding: narrow_countdown) a binary span with ticks left takes its step after two more
// branches and leaves for `moving`; the last tick of either kind takes the general step (exact
// for binary spans too, K = 0) at label 7, looped over the axes, and leaves for `last`; no
// narrow span leaves for `slow` having stored nothing. r2 counts the looped axes.
#define PATHSTREAM_T2_LEVELS(FIX0, FIX1, FIX2) \
    "adds  r8, r8, r9\n\t"                     \
    "adc   r11, r11, r12\n\t" FIX0             \
    "adds  r9, r9, r10\n\t"                    \
    "adc   r12, r12, lr\n\t" FIX1              \
    "adds  r10, r10, r5\n\t"                   \
    "adc   lr, lr, r6\n\t" FIX2
#define PATHSTREAM_T2_GENERAL                                               \
    "it    cs\n\taddcs r8, r8, r3\n\t", "it    cc\n\tsubcc r9, r9, r3\n\t", \
        "it    cs\n\taddcs r10, r10, r3\n\t"
#define PATHSTREAM_T2_BINARY "", "", ""
#define PATHSTREAM_T2_HEAD                                         \
    "ldmia %[p]!, {r3, r4, r5, r6, r8, r9, r10, r11, r12, lr}\n\t" \
    "subs  r4, r4, #1\n\t"                                         \
    "bgt   8f\n\t"                                                 \
    "bpl   7f\n\t"                                                 \
    "bcc   %l[slow]\n\t"
#define PATHSTREAM_T2_FIRST(...)                      \
    "str   r11, [%[o]], #4\n\t" PATHSTREAM_T2_LEVELS( \
        __VA_ARGS__) "stmdb %[p], {r4, r5, r6, r8, r9, r10, r11, r12, lr}\n\t"
#define PATHSTREAM_T2_NEXT(...)                            \
    "ldmia %[p]!, {r5, r6, r8, r9, r10, r11, r12, lr}\n\t" \
    "str   r11, [%[o]], #4\n\t" PATHSTREAM_T2_LEVELS(      \
        __VA_ARGS__) "stmdb %[p], {r8, r9, r10, r11, r12, lr}\n\t"
#define PATHSTREAM_T2_LOOP(...) \
    "9:\n\t" PATHSTREAM_T2_NEXT(__VA_ARGS__) "subs  r2, r2, #1\n\tbne   9b\n\t"
// The steps of every axis: FIRST, then NEXT repeated (unrolled) or looped (r2 counts).
#define PATHSTREAM_T2_UNROLLED_STEPS(REPEAT, ...) \
    PATHSTREAM_T2_FIRST(__VA_ARGS__) REPEAT(PATHSTREAM_T2_NEXT(__VA_ARGS__))
#define PATHSTREAM_T2_LOOPED_STEPS(...) \
    PATHSTREAM_T2_FIRST(__VA_ARGS__) PATHSTREAM_T2_LOOP(__VA_ARGS__)
#define PATHSTREAM_T2_CLOBBERS \
    "r3", "r4", "r5", "r6", "r8", "r9", "r10", "r11", "r12", "lr", "cc", "memory"
// The statement: SETUP, HEAD, the binary steps, the last tick's (label 7), the general steps
// (label 8). The arguments after GENERAL_STEPS are more clobbers, each after a comma.
#define PATHSTREAM_T2_TICK(SETUP, BINARY_STEPS, LAST_STEPS, GENERAL_STEPS, ...) \
    asm goto(SETUP PATHSTREAM_T2_HEAD BINARY_STEPS                              \
             "b     %l[moving]\n\t"                                             \
             "7:\n\t" LAST_STEPS                                                \
             "b     %l[last]\n\t"                                               \
             "8:\n\t" GENERAL_STEPS                                             \
             : [p] "+r"(p), [o] "+r"(o)                                         \
             : [rest] "i"(Axes - 1)                                             \
             : PATHSTREAM_T2_CLOBBERS __VA_ARGS__                               \
             : slow, last, moving)
#define PATHSTREAM_T2_ONE_AXIS                                        \
    PATHSTREAM_T2_TICK("", PATHSTREAM_T2_FIRST(PATHSTREAM_T2_BINARY), \
                       PATHSTREAM_T2_FIRST(PATHSTREAM_T2_GENERAL),    \
                       PATHSTREAM_T2_FIRST(PATHSTREAM_T2_GENERAL))
#define PATHSTREAM_T2_UNROLLED_N(REPEAT)                                                          \
    PATHSTREAM_T2_TICK("", PATHSTREAM_T2_UNROLLED_STEPS(REPEAT, PATHSTREAM_T2_BINARY),            \
                       "movs  r2, %[rest]\n\t" PATHSTREAM_T2_LOOPED_STEPS(PATHSTREAM_T2_GENERAL), \
                       PATHSTREAM_T2_UNROLLED_STEPS(REPEAT, PATHSTREAM_T2_GENERAL), , "r2")
#define PATHSTREAM_T2_LOOPED                                                                      \
    PATHSTREAM_T2_TICK("movs  r2, %[rest]\n\t", PATHSTREAM_T2_LOOPED_STEPS(PATHSTREAM_T2_BINARY), \
                       PATHSTREAM_T2_LOOPED_STEPS(PATHSTREAM_T2_GENERAL),                         \
                       PATHSTREAM_T2_LOOPED_STEPS(PATHSTREAM_T2_GENERAL), , "r2")
#endif

#if defined(PATHSTREAM_ARM_TICK_ASM) && !defined(__thumb2__)
// Thumb-1 (ARMv6-M): eight low registers, of which r7 is left to the frame pointer, and no
// conditional execution. Levels go 0, 1, 2, each reading the next level's old value, so four
// working registers carry it (r0..r3): per level the two new words are loaded, the remainders
// added (ADDS: the carry), the correction made by a short branch over one ADD of a high
// register (ip = K, lr = -K; that ADD leaves the flags alone), the quotients added (ADCS) and
// the two results stored. The jerk words come in with one LDMIA.
#define PATHSTREAM_T1_LEVEL(FIX, R, RN, Q, QN) \
    "adds  " R ", " R ", " RN "\n\t" FIX "adcs  " Q ", " QN "\n\t"
#define PATHSTREAM_T1_GENERAL                                               \
    "bcc   1f\n\tadd   r0, ip\n1:\n\t", "bcs   2f\n\tadd   r1, lr\n2:\n\t", \
        "bcc   3f\n\tadd   r0, ip\n3:\n\t"
#define PATHSTREAM_T1_BINARY "", "", ""
#define PATHSTREAM_T1_AXIS_(FIX0, FIX1, FIX2) \
    "ldr   r0, [%[p], #8]\n\t"  /* remainder 0 */                                   \
    "ldr   r1, [%[p], #12]\n\t" /* remainder 1 */                                   \
    "ldr   r2, [%[p], #20]\n\t" /* quotient 0: the setpoint */                      \
    "ldr   r3, [%[p], #24]\n\t" /* quotient 1 */                                    \
    "stmia %[o]!, {r2}\n\t" PATHSTREAM_T1_LEVEL(FIX0, "r0", "r1", "r2", "r3")       \
    "str   r0, [%[p], #8]\n\t"                                                      \
    "str   r2, [%[p], #20]\n\t"                                                     \
    "ldr   r0, [%[p], #16]\n\t" /* remainder 2 */                                   \
    "ldr   r2, [%[p], #28]\n\t" /* quotient 2 */                                    \
    PATHSTREAM_T1_LEVEL(FIX1, "r1", "r0", "r3", "r2")                               \
    "str   r1, [%[p], #12]\n\t"                                                     \
    "str   r3, [%[p], #24]\n\t"                                                     \
    "ldmia %[p]!, {r1, r3}\n\t" /* jerk remainder and quotient; p moves by 8 */     \
    PATHSTREAM_T1_LEVEL(FIX2, "r0", "r1", "r2", "r3")                               \
    "str   r0, [%[p], #8]\n\t"                                                      \
    "str   r2, [%[p], #20]\n\t"                                                     \
    "adds  %[p], #24\n\t"
#define PATHSTREAM_T1_AXIS(...) PATHSTREAM_T1_AXIS_(__VA_ARGS__)
// K into ip and -K into lr (general); p moves past K and the countdown to axis 0.
#define PATHSTREAM_T1_SETUP_GENERAL                                 \
    "ldmia %[p]!, {r0, r1}\n\t" /* K (and the countdown, unused) */ \
    "mov   ip, r0\n\t"                                              \
    "rsbs  r0, r0, #0\n\t"                                          \
    "mov   lr, r0\n\t"
#define PATHSTREAM_T1_SETUP_BINARY "adds  %[p], #8\n\t"
#define PATHSTREAM_T1_CLOBBERS "r0", "r1", "r2", "r3", "ip", "lr", "cc", "memory"
#define PATHSTREAM_T1_UNROLLED(REPEAT, SETUP, ...)                                   \
    asm volatile(".syntax unified\n\t" SETUP REPEAT(PATHSTREAM_T1_AXIS(__VA_ARGS__)) \
                 : [p] "+l"(p), [o] "+l"(o)                                          \
                 :                                                                   \
                 : PATHSTREAM_T1_CLOBBERS)
#define PATHSTREAM_T1_UNROLLED_GENERAL(REPEAT) \
    PATHSTREAM_T1_UNROLLED(REPEAT, PATHSTREAM_T1_SETUP_GENERAL, PATHSTREAM_T1_GENERAL)
#define PATHSTREAM_T1_UNROLLED_BINARY(REPEAT) \
    PATHSTREAM_T1_UNROLLED(REPEAT, PATHSTREAM_T1_SETUP_BINARY, PATHSTREAM_T1_BINARY)
#define PATHSTREAM_T1_LOOPED(SETUP, ...) \
    asm volatile(".syntax unified\n\t" SETUP "9:\n\t" PATHSTREAM_T1_AXIS(__VA_ARGS__) \
                 "subs  %[n], #1\n\t"                                               \
                 "bne   9b\n\t"                                                     \
                 : [p] "+l"(p), [o] "+l"(o), [n] "+l"(n)                            \
                 :                                                                  \
                 : PATHSTREAM_T1_CLOBBERS)
#endif
// clang-format on

namespace pathstream {

/// Writes each axis's setpoint for this tick to `out`, advances every axis one tick and counts
/// the span down. Returns the new countdown word (NarrowTick). Requires a narrow span with
/// ticks left. `Binary` must be true only for a binary span (K = 0, D a power of two): its
/// remainders are binary fractions of the word, the word's carry is the mixed-radix carry as it
/// stands, and the correction by K is skipped; the general step (Binary false) is exact for
/// binary spans too, only slower. `Compact`: Cortex-M0+ code loops over the axes instead of
/// repeating the per-axis code, which keeps it short at high axis counts. The C++ and the
/// Thumb-1 step (Thumb-2 has its own, inside narrow_tick_fast). Cost in executed instructions
/// (sim/cortex_m budget tests) on Cortex-M0+, unrolled: 25.5 per axis on average (binary 21)
/// plus 7 (binary 4). Interrupt context; touches only `state` and `out`.
template <bool Binary, bool Compact, unsigned Axes>
[[gnu::always_inline]] inline std::uint32_t narrow_tick(NarrowTick<Axes>& state, Lsb (&out)[Axes]) {
    // The countdown first: `out` (int32) may alias the state's words (uint32) as far as the
    // compiler knows, so stored after the step it would be loaded again.
    const std::uint32_t left = state.countdown - 1;
    state.countdown = left;
#if defined(PATHSTREAM_ARM_TICK_ASM) && !defined(__thumb2__)
    std::uint32_t* p = &state.bias;
    Lsb* o = out;
    if constexpr (Compact && Axes > 1) {
        std::uint32_t n = Axes;
        if constexpr (Binary) {
            PATHSTREAM_T1_LOOPED(PATHSTREAM_T1_SETUP_BINARY, PATHSTREAM_T1_BINARY);
        } else {
            PATHSTREAM_T1_LOOPED(PATHSTREAM_T1_SETUP_GENERAL, PATHSTREAM_T1_GENERAL);
        }
    } else if constexpr (Binary) {
        PATHSTREAM_FOR_AXES(PATHSTREAM_T1_UNROLLED_BINARY, 0)
    } else {
        PATHSTREAM_FOR_AXES(PATHSTREAM_T1_UNROLLED_GENERAL, 0)
    }
#else
    emit_and_step(state.axis, out, Binary ? std::uint32_t{0} : state.bias);
#endif
    return left;
}

/// What narrow_tick_fast did.
enum class FastTick : std::uint8_t {
    kPlayed,      ///< it played this tick of the narrow span in progress, not its last
    kLastPlayed,  ///< it played the span's last tick: the span is to be finished
    kNotPlayed,   ///< nothing (no narrow span in progress, or a tick it leaves to the caller)
};

/// The tick interrupt's narrow spans: plays this tick of the narrow span in progress (NarrowTick
/// at `state`; the general or the binary step, the general one for the span's last tick) and
/// says which it was; kNotPlayed (no narrow span in progress) changes nothing. Unless
/// kPlayed, `state` and `out` are as they came, for the caller's out-of-line paths. Cost in
/// executed instructions (sim/cortex_m budget tests), unrolled: Cortex-M4 15 per axis plus 2
/// (the countdown's SUBS and one branch; the LDM loads it with axis 0), binary 9 per axis plus
/// 5 (three branches and one back); compact adds 2 per axis after the first, plus 1.
/// Cortex-M0+: narrow_tick plus the C++ tests of the countdown. The caller adds its own entry
/// and return. Interrupt context; touches only `*state` and `out`.
template <bool Compact, unsigned Axes>
[[gnu::always_inline]] inline FastTick narrow_tick_fast(NarrowTick<Axes>*& state, Lsb*& out) {
#if defined(PATHSTREAM_ARM_TICK_ASM)
    // The assembly loads K and the countdown with the first axis: they must sit right before it.
    static_assert(offsetof(NarrowTick<Axes>, bias) == 0 &&
                      offsetof(NarrowTick<Axes>, countdown) == 4 &&
                      offsetof(NarrowTick<Axes>, axis) == 8 &&
                      sizeof(NarrowTick<Axes>) == 8 + sizeof(NarrowDifferences) * Axes,
                  "tick header layout");
    static_assert(sizeof(NarrowDifferences) == 32 &&
                      offsetof(NarrowDifferences, jerk_remainder) == 0 &&
                      offsetof(NarrowDifferences, jerk_quotient) == 4 &&
                      offsetof(NarrowDifferences, remainder) == 8 &&
                      offsetof(NarrowDifferences, quotient) == 20,
                  "narrow state layout");
#endif
#if defined(PATHSTREAM_T2_TICK_ASM)
    // Pinned where a caller with (this, out) in (r0, r1) has them. The LDMIAs move p on
    // before the branches to `slow` and `last`, where the state's address is taken back from
    // it: a copy kept for those paths would cost the fast path a move and a register.
    register std::uint32_t* p asm("r0") = &state->bias;
    register Lsb* o asm("r1") = out;
    if constexpr (Axes == 1) {
        PATHSTREAM_T2_ONE_AXIS;
    } else if constexpr (Compact) {
        PATHSTREAM_T2_LOOPED;
    } else {
        PATHSTREAM_FOR_AXES(PATHSTREAM_T2_UNROLLED_N, 1)
    }
    return FastTick::kPlayed;
moving:
    return FastTick::kPlayed;
last:
    state = reinterpret_cast<NarrowTick<Axes>*>(reinterpret_cast<std::uintptr_t>(p) -
                                                sizeof(NarrowTick<Axes>));
    return FastTick::kLastPlayed;
slow:
    state = reinterpret_cast<NarrowTick<Axes>*>(reinterpret_cast<std::uintptr_t>(p) -
                                                offsetof(NarrowTick<Axes>, axis) -
                                                sizeof(NarrowDifferences));
    out = o;
    return FastTick::kNotPlayed;
#else
    Lsb(&o)[Axes] = *reinterpret_cast<Lsb(*)[Axes]>(out);
    const std::uint32_t countdown = state->countdown;
    if (narrow_fast(countdown, false)) [[likely]] {
        narrow_tick<false, Compact>(*state, o);
        return FastTick::kPlayed;
    }
    if (narrow_fast(countdown, true)) [[likely]] {
        narrow_tick<true, Compact>(*state, o);
        return FastTick::kPlayed;
    }
    if (countdown == narrow_countdown(1, false) || countdown == narrow_countdown(1, true)) {
        // The last tick: the general step is exact for binary spans too (their K is 0).
        narrow_tick<false, Compact>(*state, o);
        return FastTick::kLastPlayed;
    }
    return FastTick::kNotPlayed;
#endif
}

}  // namespace pathstream

#if defined(PATHSTREAM_ARM_TICK_ASM)
#undef PATHSTREAM_ARM_TICK_ASM
#undef PATHSTREAM_REPEAT_0
#undef PATHSTREAM_REPEAT_1
#undef PATHSTREAM_REPEAT_2
#undef PATHSTREAM_REPEAT_3
#undef PATHSTREAM_REPEAT_4
#undef PATHSTREAM_REPEAT_5
#undef PATHSTREAM_REPEAT_6
#undef PATHSTREAM_REPEAT_7
#undef PATHSTREAM_REPEAT_8
#undef PATHSTREAM_FOR_AXES
#if defined(__thumb2__)
#undef PATHSTREAM_T2_TICK_ASM
#undef PATHSTREAM_T2_LEVELS
#undef PATHSTREAM_T2_GENERAL
#undef PATHSTREAM_T2_BINARY
#undef PATHSTREAM_T2_HEAD
#undef PATHSTREAM_T2_FIRST
#undef PATHSTREAM_T2_NEXT
#undef PATHSTREAM_T2_LOOP
#undef PATHSTREAM_T2_UNROLLED_STEPS
#undef PATHSTREAM_T2_LOOPED_STEPS
#undef PATHSTREAM_T2_CLOBBERS
#undef PATHSTREAM_T2_TICK
#undef PATHSTREAM_T2_ONE_AXIS
#undef PATHSTREAM_T2_UNROLLED_N
#undef PATHSTREAM_T2_LOOPED
#else
#undef PATHSTREAM_T1_LEVEL
#undef PATHSTREAM_T1_GENERAL
#undef PATHSTREAM_T1_BINARY
#undef PATHSTREAM_T1_AXIS_
#undef PATHSTREAM_T1_AXIS
#undef PATHSTREAM_T1_SETUP_GENERAL
#undef PATHSTREAM_T1_SETUP_BINARY
#undef PATHSTREAM_T1_CLOBBERS
#undef PATHSTREAM_T1_UNROLLED
#undef PATHSTREAM_T1_UNROLLED_GENERAL
#undef PATHSTREAM_T1_UNROLLED_BINARY
#undef PATHSTREAM_T1_LOOPED
#endif
#endif
