// Bare-metal image for the instruction budgets, run under qemu with the insn_count plugin
// (plugin/insn_count.c) and read by host/budget_report.cpp.
//
// For A = 1, 2, 3, 4, 8 axes it streams spans through SetpointStream<A, 16> in phases:
//   narrow: spans of n = 60 ticks, all four bases (32-bit remainders, D not a power of two:
//           the general step with its correction by K), S = 16
//   binary: spans of n = 8 ticks, Hermite, Bezier and Catmull-Rom (D = 2^m: the step without
//           correction); the planner streams Hermite spans of ticks_per_span = 8 ticks, S = 16
//   wide:   spans of n = 2048 ticks (D >= 2^32, 64-bit remainders), S = 4
// and for each kind three phases on the same control values: (n, S spans), (2n, S spans),
// (n, 2S spans), plus a phase of push() alone. Differences between phases cancel everything
// that does not scale with the tick count:
//   (2n, S) - (n, S): the steady per-tick cost (same number of span switches);
//   (n, 2S) - (n, S): S more spans of n ticks, each with its switch and its push.
// Every phase is bracketed by calls to budget_mark(), whose address the plugin watches: it
// snapshots its counters there. tick() is measured through budget_tick_<A>, an out-of-line
// function whose body is exactly SetpointStream::tick inlined (same arguments: the stream and
// the output array), so its address range is tick()'s code.
// It ends with Horner phases (evaluate_at per call, n = 64 and n = 65536) and a calibration loop
// whose exact instruction count is known, which checks the counting method itself.
#include <cstdint>
#include <new>

#include "pathstream/device/jerk_moves.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/input_shaper.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/tick_cubic.hpp"
#include "semihosting.hpp"
#include "workload.hpp"

namespace {

using pathstream::Lsb;
using pathstream::Status;
using pathstream::TickState;

constexpr std::uint32_t kCapacity = 16;
template <unsigned A>
using Stream = pathstream::SetpointStream<A, kCapacity>;

template <unsigned A>
using Device = pathstream::device::MotionDevice<A, kCapacity>;

// The input shaper's history in the budget image: 256 ticks (a 40 Hz 3-hump EI at 1 kHz needs
// 51), so that four axes fit the micro:bit's RAM beside the stack.
constexpr std::uint32_t kShaperHistory = 256;
template <unsigned A>
using Shaper = pathstream::InputShaper<A, kShaperHistory>;

// One stream or device at a time lives here (the micro:bit has 16 KiB of RAM).
constexpr std::size_t kLargest(std::size_t a, std::size_t b) {
    return a > b ? a : b;
}
constexpr std::size_t kArenaBytes =
    kLargest(kLargest(sizeof(Stream<8>), sizeof(Device<2>)), sizeof(Shaper<4>));
alignas(8) unsigned char g_arena[kArenaBytes];
Lsb g_out[8];
bool g_failed = false;

}  // namespace

/// The plugin snapshots its counters whenever this function's first instruction executes.
extern "C" [[gnu::noinline, gnu::used]] void budget_mark(std::uint32_t id) {
    asm volatile("" : : "r"(id) : "memory");
}

/// Exactly 2 * iterations + 1 instructions (iterations >= 1): the plugin's self-check.
extern "C" [[gnu::naked, gnu::noinline, gnu::used]] void budget_calibrate(std::uint32_t) {
    // GCC hands Thumb-1 inline asm to the assembler in divided syntax; ask for unified (GCC
    // re-emits .syntax unified after every asm statement itself).
    asm volatile(
        ".syntax unified\n\t"
        "1: subs r0, r0, #1\n\t"
        "   bne 1b\n\t"
        "   bx lr\n\t");
}

// tick() as an out-of-line function per axis count: budget_tick_<A>.
#define PATHSTREAM_BUDGET_TICK(A)                                                            \
    extern "C"                                                                               \
        [[gnu::noinline, gnu::used]] TickState budget_tick_##A(Stream<A>& s, Lsb(&out)[A]) { \
        return s.tick(out);                                                                  \
    }
PATHSTREAM_BUDGET_TICK(1)
PATHSTREAM_BUDGET_TICK(2)
PATHSTREAM_BUDGET_TICK(3)
PATHSTREAM_BUDGET_TICK(4)
PATHSTREAM_BUDGET_TICK(8)

// InputShaper::shape as an out-of-line function per axis count: budget_shape_<A>.
#define PATHSTREAM_BUDGET_SHAPE(A)                                 \
    extern "C" [[gnu::noinline, gnu::used]] void budget_shape_##A( \
        Shaper<A>& s, const Lsb(&command)[A], Lsb(&out)[A]) {      \
        s.shape(command, out);                                     \
    }
PATHSTREAM_BUDGET_SHAPE(1)
PATHSTREAM_BUDGET_SHAPE(2)
PATHSTREAM_BUDGET_SHAPE(4)

namespace {

template <unsigned A>
TickState tick_of(Stream<A>& s, Lsb (&out)[A]);
template <>
TickState tick_of<1>(Stream<1>& s, Lsb (&out)[1]) {
    return budget_tick_1(s, out);
}
template <>
TickState tick_of<2>(Stream<2>& s, Lsb (&out)[2]) {
    return budget_tick_2(s, out);
}
template <>
TickState tick_of<3>(Stream<3>& s, Lsb (&out)[3]) {
    return budget_tick_3(s, out);
}
template <>
TickState tick_of<4>(Stream<4>& s, Lsb (&out)[4]) {
    return budget_tick_4(s, out);
}
template <>
TickState tick_of<8>(Stream<8>& s, Lsb (&out)[8]) {
    return budget_tick_8(s, out);
}

constexpr int kPoolSize = 4;
using Bases = pathstream::Basis[kPoolSize];
using pathstream::Basis;
// Every basis (the last must be Hermite, see make_pool); for n a power of two only those whose
// D = s n^3 is one then too (B-spline: s = 6).
constexpr Bases kAllBases = {Basis::kUniformBSpline, Basis::kCatmullRom, Basis::kBezier,
                             Basis::kHermite};
constexpr Bases kBinaryBases = {Basis::kCatmullRom, Basis::kHermite, Basis::kBezier,
                                Basis::kHermite};

/// Four spans of `n` ticks of the given bases, gentle random control values, chained into a
/// closed loop: push() accepts only a span that starts where the previous one ends, and the
/// phases push the pool round and round from `start` (pool[0]'s tick-0 value). Each span is
/// translated (the same offset on its position control values) to start at the previous
/// one's end; the last, a Hermite span, then ends at pool[0]'s start (its P1). The end points
/// (u = 0 and u = 1) do not depend on n, so the loop stays closed when n changes.
/// Returns false if the core refuses a span (it cannot: the values are gentle).
template <unsigned A>
bool make_pool(pathstream::workload::SplitMix64& rng, std::uint32_t n, const Bases& bases,
               pathstream::Span<A> (&pool)[kPoolSize], Lsb (&start)[A]) {
    for (int i = 0; i < kPoolSize; ++i) {
        pool[i].basis = bases[i];
        pool[i].ticks = n;
        pool[i].tag = static_cast<std::uint32_t>(i + 1);
        for (unsigned a = 0; a < A; ++a) {
            const std::int32_t base = rng.between(-1000000, 1000000);
            for (int j = 0; j < 4; ++j) {
                const bool tangent = pool[i].basis == pathstream::Basis::kHermite && j >= 2;
                pool[i].control[a][j] =
                    tangent ? rng.between(-300000, 300000) : base + rng.between(-100000, 100000);
            }
        }
    }
    using pathstream::workload::span_start;
    if (span_start(pool[0], start) != Status::kOk) return false;
    Lsb end[A];  // pool[i - 1]'s end point
    for (int i = 1; i < kPoolSize; ++i) {
        Lsb own_start[A];
        pathstream::SpanTiming timing;
        if (pathstream::make_span_timing(pool[i - 1].basis, n, timing) != Status::kOk) return false;
        for (unsigned a = 0; a < A; ++a) {
            pathstream::TickCubic cubic;
            if (pathstream::make_tick_cubic(pool[i - 1].basis, pool[i - 1].control[a], timing,
                                            cubic) != Status::kOk ||
                pathstream::evaluate_at(cubic, timing, n, end[a]) != Status::kOk) {
                return false;
            }
        }
        if (span_start(pool[i], own_start) != Status::kOk) return false;
        if (!pathstream::workload::translate(pool[i], own_start, end)) return false;
    }
    // Close the loop: the Hermite span ends at its P1.
    for (unsigned a = 0; a < A; ++a) pool[kPoolSize - 1].control[a][1] = start[a];
    return pool[kPoolSize - 1].basis == pathstream::Basis::kHermite;
}

std::uint32_t g_phase = 0;

void report_phase(const char* kind, unsigned axes, std::uint32_t n, std::uint32_t spans,
                  std::uint64_t ticks, std::uint64_t calls, bool ok) {
    cortex_m::Line line;
    line.text("phase id=")
        .dec(g_phase)
        .text(" kind=")
        .text(kind)
        .text(" axes=")
        .dec(axes)
        .text(" n=")
        .dec(n)
        .text(" spans=")
        .dec(spans)
        .text(" ticks=")
        .dec(ticks)
        .text(" calls=")
        .dec(calls)
        .text(" ok=")
        .dec(ok ? 1 : 0)
        .end();
    if (!ok) g_failed = true;
    ++g_phase;
}

/// One streaming phase: a fresh stream, `spans` spans of `n` ticks pushed as room appears
/// (the producer runs between ticks, as a task would), ticked until all are consumed.
template <unsigned A>
[[gnu::noinline]] void stream_phase(const char* kind, const pathstream::Span<A> (&pool)[kPoolSize],
                                    const Lsb (&start)[A], std::uint32_t n, std::uint32_t spans) {
    budget_mark(2 * g_phase);
    Stream<A>& s = *new (g_arena) Stream<A>(start);
    std::uint32_t pushed = 0;
    bool ok = true;
    while (pushed < spans && s.free_slots() != 0) {
        ok &= s.push(pool[pushed % kPoolSize]) == Status::kOk;
        ++pushed;
    }
    const std::uint64_t ticks = std::uint64_t{spans} * n;
    for (std::uint64_t t = 0; t < ticks; ++t) {
        (void)tick_of<A>(s, reinterpret_cast<Lsb(&)[A]>(g_out));
        if (pushed < spans && s.free_slots() != 0) {
            ok &= s.push(pool[pushed % kPoolSize]) == Status::kOk;
            ++pushed;
        }
    }
    budget_mark(2 * g_phase + 1);
    ok &= s.spans_completed() == spans && s.queued_spans() == 0 && s.ticks_executed() == ticks;
    report_phase(kind, A, n, spans, ticks, 0, ok);
}

/// push() alone: a fresh stream filled with kCapacity spans; cost per push (validation and
/// prepare_span, i.e. make_tick_cubic and start_differences on every axis).
template <unsigned A>
[[gnu::noinline]] void push_phase(const char* kind, const pathstream::Span<A> (&pool)[kPoolSize],
                                  const Lsb (&start)[A]) {
    Stream<A>& s = *new (g_arena) Stream<A>(start);
    bool ok = true;
    budget_mark(2 * g_phase);
    for (std::uint32_t i = 0; i < kCapacity; ++i) {
        ok &= s.push(pool[i % kPoolSize]) == Status::kOk;
    }
    budget_mark(2 * g_phase + 1);
    report_phase(kind, A, pool[0].ticks, kCapacity, 0, kCapacity, ok);
}

/// The phases of one kind of span: (n, S), (2n, S), (n, 2S) on the same control values (only
/// the tick count changes, and S is a multiple of the pool size, so the (n, 2S) phase runs
/// the (n, S) phase's spans twice), then push() alone.
template <unsigned A>
void kind_phases(pathstream::workload::SplitMix64& rng, const char* kind, const char* push_kind,
                 const Bases& bases, std::uint32_t n, std::uint32_t spans) {
    pathstream::Span<A> pool[kPoolSize];
    Lsb start[A];
    if (!make_pool<A>(rng, n, bases, pool, start)) {
        cortex_m::write("budget image: make_pool failed\n");
        g_failed = true;
    }
    stream_phase<A>(kind, pool, start, n, spans);
    for (auto& span : pool) span.ticks = 2 * n;
    stream_phase<A>(kind, pool, start, 2 * n, spans);
    for (auto& span : pool) span.ticks = n;
    stream_phase<A>(kind, pool, start, n, 2 * spans);
    push_phase<A>(push_kind, pool, start);
}

template <unsigned A>
void stream_phases(pathstream::workload::SplitMix64& rng) {
    // Narrow: n = 60 and 120, D = s n^3 < 2^32 and never a power of two.
    kind_phases<A>(rng, "narrow", "push_narrow", kAllBases, 60, 16);
    // Binary: n = 8 and 16, D = 2^9 .. 2^13.
    kind_phases<A>(rng, "binary", "push_binary", kBinaryBases, 8, 16);
    // Wide: n = 2048 (D >= 2^33 for every basis).
    kind_phases<A>(rng, "wide", "push_wide", kAllBases, 2048, 4);
}

/// evaluate_at at `calls` ticks spread over a span of n ticks; cost per call.
[[gnu::noinline]] void horner_phase(pathstream::workload::SplitMix64& rng, std::uint32_t n,
                                    std::uint32_t calls) {
    pathstream::SpanTiming timing;
    pathstream::TickCubic cubic;
    std::int32_t control[4];
    for (int j = 0; j < 4; ++j) control[j] = rng.between(-50000000, 50000000);
    bool ok =
        pathstream::make_span_timing(pathstream::Basis::kUniformBSpline, n, timing) == Status::kOk;
    ok &= pathstream::make_tick_cubic(pathstream::Basis::kUniformBSpline, control, timing, cubic) ==
          Status::kOk;
    budget_mark(2 * g_phase);
    for (std::uint32_t i = 0; i < calls; ++i) {
        ok &=
            pathstream::evaluate_at(cubic, timing, (i * 7919u) % (n + 1), g_out[0]) == Status::kOk;
    }
    budget_mark(2 * g_phase + 1);
    report_phase("horner", 1, n, 1, 0, calls, ok);
}

/// The whole device: MotionDevice<A, 16> (task side and tick side) runs one straight move of
/// `spans` spans of `n` ticks at 4 LSB per tick on every axis: one span accelerating from rest,
/// cruising spans, one span braking to rest, sent as wire batches of up to 8 whenever 8 slots
/// are free (a bus task would), the device ticked until it rests at the end. The phases
/// (n, S) and (2n, S) send the same number of batches, so their difference is S n ticks of
/// MotionDevice::tick in steady state (the status publication and the mailbox reads
/// included) plus the driver loop's free-slot check per tick. Total instructions, no ranges.
template <unsigned A>
[[gnu::noinline]] void device_phase(std::uint32_t n, std::uint32_t spans) {
    namespace dev = pathstream::device;
    const Lsb start[A] = {};
    budget_mark(2 * g_phase);
    Device<A>& d = *new (g_arena) Device<A>(start);
    dev::MotionLimits<A> limits;
    limits.tick_hz = 1000;
    for (unsigned a = 0; a < A; ++a) limits.axis[a] = {1000000, 100000000};
    bool ok = d.configure(limits) == Status::kOk;
    constexpr std::int32_t kVelocity = 4;  // LSB per tick
    const auto span_ticks = static_cast<std::int32_t>(n);
    std::int32_t position = 0;
    std::uint32_t sent = 0;
    auto send_batch = [&](std::uint32_t count) {
        std::uint8_t bytes[8 * (4 + 12 * A)];
        std::size_t length = 0;
        for (std::uint32_t i = 0; i < count; ++i, ++sent) {
            dev::WireSpan w;
            w.ticks = n;
            const bool first = sent == 0, last = sent + 1 == spans;
            const std::int32_t cruise = kVelocity * span_ticks;
            const std::int32_t t0 = first ? 0 : cruise, t1 = last ? 0 : cruise;
            position += first || last ? cruise / 2 : cruise;  // a parabola from or to rest
            for (unsigned a = 0; a < A; ++a) {
                w.end[a] = position;
                w.start_tangent[a] = t0;
                w.end_tangent[a] = t1;
            }
            length += dev::encode_wire_span(w, A, bytes + length, sizeof bytes - length);
        }
        ok &= d.accept_batch(sent - count + 1, static_cast<std::uint16_t>(count), bytes, length) ==
              Status::kOk;
    };
    send_batch(8);
    ok &= d.command(dev::Command::kStart) == Status::kOk;
    const std::uint64_t ticks = std::uint64_t{spans} * n;
    for (std::uint64_t t = 0; t < ticks; ++t) {
        d.tick(reinterpret_cast<Lsb(&)[A]>(g_out));
        if (sent < spans && d.free_slots() >= 8) send_batch(spans - sent < 8 ? spans - sent : 8);
    }
    budget_mark(2 * g_phase + 1);
    ok &= d.ticks_executed() == ticks && d.queued_spans() == 0 && sent == spans;
    report_phase("device", A, n, spans, ticks, 0, ok);
}

/// The device's controlled stop, planned in the tick that takes a hold: plan_jerk_stop under the
/// pen plotter's jerk limit (10^5 mm/s^3 at 1 um and 1 kHz: 0.1 LSB/tick^3; 250 LSB/tick,
/// 3 LSB/tick^2) or plan_stop without one, from a seeded moving state (8-tick spans, up to
/// 200 LSB/tick, decelerating at up to 1 LSB/tick^2). One call per phase: the report shows the
/// spread.
template <unsigned A>
[[gnu::noinline]] void stop_phase(pathstream::workload::SplitMix64& rng, bool jerk) {
    namespace dev = pathstream::device;
    dev::MotionLimits<A> limits;
    limits.tick_hz = 1000;
    for (unsigned a = 0; a < A; ++a) {
        limits.axis[a].max_velocity = 250000;
        limits.axis[a].max_acceleration = 3000000;
        limits.axis[a].max_jerk = jerk ? 1000000u : 0u;
    }
    constexpr std::uint32_t kTicks = 8;
    constexpr std::int64_t kQ = 64 * 256;  // the acceleration's denominator
    Lsb position[A];
    std::int32_t tangent[A];
    dev::TickAcceleration acceleration[A];
    for (unsigned a = 0; a < A; ++a) {
        position[a] = rng.between(-1000000, 1000000);
        tangent[a] = rng.between(-200 * kTicks, 200 * kTicks);
        const std::int64_t against = tangent[a] > 0 ? -1 : 1;
        acceleration[a] =
            dev::TickAcceleration{against * rng.between(0, kQ), static_cast<std::uint64_t>(kQ)};
    }
    dev::JerkMove<A> move;
    budget_mark(2 * g_phase);
    const Status s =
        jerk ? dev::plan_jerk_stop(position, tangent, kTicks, acceleration, limits, move)
             : dev::plan_stop(position, tangent, kTicks, limits, move.span[0]);
    budget_mark(2 * g_phase + 1);
    report_phase(jerk ? "jerk_stop" : "plain_stop", A, kTicks, jerk ? move.count : 1, 0, 1,
                 s == Status::kOk);
}

template <unsigned A>
void shape_of(Shaper<A>& s, const Lsb (&command)[A], Lsb (&out)[A]);
template <>
void shape_of<1>(Shaper<1>& s, const Lsb (&command)[1], Lsb (&out)[1]) {
    budget_shape_1(s, command, out);
}
template <>
void shape_of<2>(Shaper<2>& s, const Lsb (&command)[2], Lsb (&out)[2]) {
    budget_shape_2(s, command, out);
}
template <>
void shape_of<4>(Shaper<4>& s, const Lsb (&command)[4], Lsb (&out)[4]) {
    budget_shape_4(s, command, out);
}

/// The input shaper in the tick: `ticks` calls of shape() with `taps` taps on every axis
/// (delays spread over 0..50, weights summing to 2^16), the command a ramp that moves every
/// tick. The report takes the difference of runs of `ticks` and 2 * `ticks`: the steady cost
/// per tick with the driver loop's few instructions.
template <unsigned A>
[[gnu::noinline]] void shaper_phase(std::uint32_t taps, std::uint32_t ticks) {
    const Lsb start[A] = {};
    Shaper<A>& s = *new (g_arena) Shaper<A>(start);
    pathstream::ShaperTap tap[pathstream::kMaxShaperTaps];
    std::uint32_t left = pathstream::kShaperWeightOne;
    for (std::uint32_t i = 0; i < taps; ++i) {
        tap[i].delay = i * 50 / (taps - 1);
        tap[i].weight = i + 1 == taps ? left : pathstream::kShaperWeightOne / taps;
        left -= tap[i].weight;
    }
    bool ok = true;
    for (unsigned a = 0; a < A; ++a) ok &= s.configure(a, tap, taps) == Status::kOk;
    Lsb command[A] = {};
    budget_mark(2 * g_phase);
    for (std::uint32_t t = 0; t < ticks; ++t) {
        for (unsigned a = 0; a < A; ++a) command[a] += static_cast<Lsb>(a + 1);
        shape_of<A>(s, command, reinterpret_cast<Lsb(&)[A]>(g_out));
    }
    budget_mark(2 * g_phase + 1);
    // After `ticks` ramp ticks past the longest delay the output lags the command by the
    // taps' mean delay times the ramp's slope; it must have moved and stayed below it.
    ok &= g_out[0] > 0 && g_out[0] <= command[0];
    report_phase("shaper", A, taps, 1, ticks, 0, ok);
}

template <unsigned A>
void shaper_phases() {
    constexpr std::uint32_t kTapCounts[] = {3, 5, 9};
    for (std::uint32_t taps : kTapCounts) {
        shaper_phase<A>(taps, 200);
        shaper_phase<A>(taps, 400);
    }
}

[[gnu::noinline]] void calibration_phase(std::uint32_t iterations) {
    budget_mark(2 * g_phase);
    budget_calibrate(iterations);
    budget_mark(2 * g_phase + 1);
    report_phase("calibrate", 0, iterations, 0, 0, 1, true);
}

}  // namespace

int main() {
    pathstream::workload::SplitMix64 rng(0xb0d6e7u);
    cortex_m::write("budget image: SetpointStream<A, 16>, narrow n=60, binary n=8, wide n=2048\n");
    calibration_phase(1000);
    stream_phases<1>(rng);
    stream_phases<2>(rng);
    stream_phases<3>(rng);
    stream_phases<4>(rng);
    stream_phases<8>(rng);
    horner_phase(rng, 64, 64);     // |Q| < 2^64: one 64-bit division
    horner_phase(rng, 65536, 64);  // |Q| >= 2^64: the bit-serial 128/64 division
    device_phase<2>(60, 32);
    device_phase<2>(120, 32);
    for (int i = 0; i < 8; ++i) stop_phase<2>(rng, true);
    for (int i = 0; i < 4; ++i) stop_phase<2>(rng, false);
    shaper_phases<1>();
    shaper_phases<2>();
    shaper_phases<4>();
    cortex_m::Line line;
    line.text("budget done phases=").dec(g_phase).text(g_failed ? " FAILED" : " ok").end();
    return g_failed ? 1 : 0;
}
