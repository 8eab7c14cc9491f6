// A span as the host sends it, and the same span prepared for the per-tick loop.
#pragma once

#include <cstdint>

#include "pathstream/basis.hpp"
#include "pathstream/forward_difference.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"

namespace pathstream {

/// Upper bound on axes per span; a build picks its own Axes (1..kMaxAxes) at compile time.
inline constexpr unsigned kMaxAxes = 8;

/// One cubic piece of the path on all axes, lasting `ticks` ticks. Plain value, 16 bytes per
/// axis plus a header; what the wire protocols carry.
template <unsigned Axes>
struct Span {
    static_assert(Axes >= 1 && Axes <= kMaxAxes, "1 to 8 axes");
    Basis basis = Basis::kUniformBSpline;
    std::uint32_t ticks = 1;             ///< n, 1..kMaxSpanTicks
    std::uint32_t tag = 0;               ///< caller's label (e.g. a sequence number), kept
    std::uint8_t outputs = 0;            ///< discrete outputs while it plays (kOutputPenDown...)
    std::int32_t control[Axes][4] = {};  ///< per axis: P0..P3 (Hermite: P0, P1, T0, T1)
};

/// Bits of Span::outputs. The device applies a span's outputs at its first tick, so a pen
/// change happens exactly at a span boundary (the planner puts a dwell span there).
inline constexpr std::uint8_t kOutputPenDown = 1u << 0;
/// The spindle (or laser) runs: G-code M3 or M4 until M5.
inline constexpr std::uint8_t kOutputSpindle = 1u << 1;
/// With kOutputSpindle: it turns counter-clockwise (M4); without, clockwise (M3).
inline constexpr std::uint8_t kOutputSpindleReverse = 1u << 2;
/// Mist coolant (M7) and flood coolant (M8), until M9.
inline constexpr std::uint8_t kOutputMist = 1u << 3;
inline constexpr std::uint8_t kOutputFlood = 1u << 4;
/// The machine functions among the outputs. Unlike the pen, the device keeps them as the last
/// played span left them while the job is held, paused, underrun or stopping (a spindle is not
/// stopped by a feed hold), and drops them only when the job ends or stops, a fault or the
/// e-stop; the planner changes them only where the motion rests.
inline constexpr std::uint8_t kOutputMachineMask =
    kOutputSpindle | kOutputSpindleReverse | kOutputMist | kOutputFlood;
/// Every defined bit: a span with any other bit set is refused.
inline constexpr std::uint8_t kOutputKnownMask = kOutputPenDown | kOutputMachineMask;

/// What a queue entry carries besides the motion, for whoever consumes the queue; the stream
/// itself never reads it. A device stamps each span with the queue epoch it was accepted in,
/// its job, the end marker, and the Hermite chord and tangents it needs to plan a stop at the
/// span's end or inside it (device/motion_device.hpp); written by the producer before the
/// entry is published.
template <unsigned Axes>
struct SpanStamp {
    std::uint32_t epoch = 0;
    std::uint32_t job = 0;
    std::int32_t end_tangent[Axes] = {};    ///< Hermite T1 per axis (LSB per span)
    std::int32_t start_tangent[Axes] = {};  ///< Hermite T0 per axis (LSB per span)
    std::int32_t chord[Axes] = {};          ///< P1 - P0 per axis (LSB, |.| <= 2^28)
    bool job_end = false;
    bool pause_after = false;  ///< the device holds at this span's end (it ends at rest)
};

/// The narrow span in progress as the tick interrupt steps it: the consumer's own copy of the
/// span's K, countdown and states, made when the span starts (SetpointStream keeps it first,
/// at offset 0, so that the tick reaches it from `this` without loading a pointer; one LDM
/// loads K, the countdown and axis 0 on Cortex-M4). Consumer context only.
template <unsigned Axes>
struct NarrowTick {
    std::uint32_t bias = 0;        ///< K = 2^32 - D, or 0 when D is a power of two
    std::uint32_t countdown = 0;   ///< encoded ticks left (narrow_countdown), 0: none
    NarrowDifferences axis[Axes];  ///< meaningful only while countdown != 0
};

/// NarrowTick::countdown for a span with `ticks_left` >= 1 ticks to supply, this one included:
/// the count itself for the general step, 2^31 - 1 + the count when D is a power of two (the
/// binary step). Then one SUBS of 1 tells the cases apart by its flags: GT for a general span
/// with ticks left after this one (the fast path), MI with carry for a binary one, PL (zero,
/// or 2^31 - 1 with overflow) for the last tick of either, carry clear for 0 (no narrow span).
constexpr std::uint32_t narrow_countdown(std::uint32_t ticks_left, bool binary) {
    return binary ? ticks_left + 0x7fffffffu : ticks_left;
}
/// True when a NarrowTick::countdown stands for a tick the fast path plays: ticks left after it,
/// general (binary false) or binary.
constexpr bool narrow_fast(std::uint32_t countdown, bool binary) {
    return binary ? static_cast<std::int32_t>(countdown - 1) < -1
                  : static_cast<std::int32_t>(countdown) > 1;
}

/// A span validated and converted to forward-differencing state at its first tick.
/// Holds either narrow or wide state for all axes (they share D). ~40 or ~48 bytes per axis.
template <unsigned Axes>
struct PreparedSpan {
    // A narrow span's K, countdown and states, laid out as NarrowTick: the consumer copies
    // them to its tick state when the span starts, and never writes to the queue entry.
    std::uint32_t narrow_bias = 0;  ///< narrow: K = 2^32 - D, or 0 when D is a power of two
    std::uint32_t countdown = 0;    ///< at its first tick: narrow_countdown() when narrow, the
                                    ///< ticks when wide (the consumer counts down its own copy)
    union {
        NarrowDifferences narrow[Axes];
        WideDifferences wide_state[Axes];
    };
    std::uint32_t ticks = 0;
    std::uint32_t tag = 0;
    std::uint64_t bias = 0;  ///< K = 2^W - D (its low 32 bits when narrow), 0 when D = 2^m
    bool wide = false;
    std::uint8_t outputs = 0;  ///< Span::outputs, applied while the span plays
    SpanStamp<Axes> stamp;     ///< the producer's stamp (never read by the tick loop)
    PreparedSpan() : narrow{} {}
};

/// A span that passed validation: its timing and exact cubic per axis, ready to prepare.
template <unsigned Axes>
struct ValidatedSpan {
    SpanTiming timing;
    TickCubic cubic[Axes];
    std::uint32_t tag = 0;
    std::uint8_t outputs = 0;
};

/// Checks `span` on every axis (make_span_timing, make_tick_cubic) into `out`. Returns the
/// first failure; `out` is then unspecified. Cost: a few hundred instructions per axis on
/// Cortex-M4. Task context.
template <unsigned Axes>
[[nodiscard]] Status validate_span(const Span<Axes>& span, ValidatedSpan<Axes>& out) {
    if (Status s = make_span_timing(span.basis, span.ticks, out.timing); s != Status::kOk) return s;
    for (unsigned axis = 0; axis < Axes; ++axis) {
        if (Status s = make_tick_cubic(span.basis, span.control[axis], out.timing, out.cubic[axis]);
            s != Status::kOk) {
            return s;
        }
    }
    out.tag = span.tag;
    out.outputs = span.outputs;
    return Status::kOk;
}

/// Writes the prepared form (forward-differencing state at tick 0) of a validated span.
/// Cannot fail. Cost: per axis one start_differences (four 128/64 divisions). Task context.
template <unsigned Axes>
void prepare_validated(const ValidatedSpan<Axes>& v, PreparedSpan<Axes>& out) {
    const bool narrow = is_narrow(v.timing);
    for (unsigned axis = 0; axis < Axes; ++axis) {
        const Status s = narrow
                             ? start_differences(v.cubic[axis], v.timing, 0, out.narrow[axis])
                             : start_differences(v.cubic[axis], v.timing, 0, out.wide_state[axis]);
        (void)s;  // cannot fail: tick 0 is inside every span, and the bounds are proven
    }
    out.ticks = v.timing.ticks;
    out.tag = v.tag;
    out.outputs = v.outputs;
    out.wide = !narrow;
    out.bias = difference_bias(v.timing);
    // Narrow: K (0 for a binary span) and the tick state's countdown; wide: the ticks.
    out.narrow_bias = narrow ? static_cast<std::uint32_t>(out.bias) : 0u;
    out.countdown = narrow_countdown(v.timing.ticks, narrow && is_binary(v.timing));
}

/// Validates `span` on every axis and writes its prepared form to `out`. Either every axis
/// passes and `out` is fully written, or the first failure is returned and `out` is left as
/// it was on all axes. Task context, never the tick interrupt.
template <unsigned Axes>
[[nodiscard]] Status prepare_span(const Span<Axes>& span, PreparedSpan<Axes>& out) {
    ValidatedSpan<Axes> v;
    if (Status s = validate_span(span, v); s != Status::kOk) return s;
    prepare_validated(v, out);
    return Status::kOk;
}

}  // namespace pathstream
