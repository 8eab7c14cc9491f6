// bench_eval: how fast, and how exact, is each way of turning one path's cubic spans into
// integer setpoints?
//
// The path: a closed uniform cubic B-spline through kControlPoints integer control points of
// a 7-petal rose (amplitude 1e6 LSB, centred at (1.1e6, 1.05e6) LSB), 2 axes, n ticks per
// span (default: n = 64, a narrow span with 32-bit remainders, and n = 4096, a wide one with
// 64-bit remainders). Span i uses control points P[i..i+3] (indices mod the count), so the
// path has one span per control point and ends where it starts.
//
// The methods, all producing the same setpoints (one setpoint = both axes at one tick; a span
// of n ticks supplies its ticks 0..n-1):
//   * exact FD, SetpointStream::tick  : the core's consumer with the spans already queued;
//                                        only the tick() loop is timed (the tick interrupt).
//   * exact FD, push + tick            : the same, with prepare_span (SetpointStream::push)
//                                        of every span inside the timed region.
//   * exact FD, raw emit_and_step      : DifferenceState of spans prepared once, stepped by
//                                        emit_and_step (the state copy per span is timed).
//     These three are the tick interrupt's path: one tick per call, the state loaded from
//     memory and stored back every tick, as an interrupt must keep it between ticks.
//   * exact FD, SetpointStream::tick_many: a second queued stream, 256 ticks per call
//                                        (emit_span_ticks inside, the state in registers).
//   * exact FD, emit_span_ticks        : THE LIKE-FOR-LIKE ROW. Spans prepared once (as the
//                                        baseline's coefficients are), each stepped by
//                                        emit_span_ticks into a 256-setpoint buffer that the
//                                        checksum then reads: the same work per setpoint as
//                                        double Horner (every tick of every span, both axes,
//                                        each setpoint handed to the same checksum), plus one
//                                        store and one load per value that the baseline,
//                                        whose values stay in registers, does not do.
//   * integer Horner, evaluate_at      : the core's 128-bit Horner and 128/64 division, per
//                                        axis per tick (make_tick_cubic done beforehand).
//   * double Horner                    : THE BASELINE. The same cubic per span, coefficients
//                                        M*P/6 in double, Horner in u = k * (1/n), rounded
//                                        with floor(v + 0.5) (the core's halves-up rule).
//   * float32 FD                       : forward differencing in float of the same cubic,
//                                        restarted from the span's exact start every span.
//   * Eigen::Spline<double,2,3>        : unsupported/Eigen/Splines on the same B-spline: knots
//                                        0, 1, ..., N+6 (uniform, unclamped) and control points
//                                        P[0..N+2] (the first three repeated at the end), so its
//                                        parameter range [3, N+3] reproduces exactly the N
//                                        uniform spans; span i tick k is u = i + 3 + k/n.
//                                        Evaluation is Piegl & Tiller A2.1 (span search) and
//                                        A2.2 (Cox-de Boor basis functions), then the weighted
//                                        sum of the four control points.
//
// How the figures are measured: the thread's CPU time (CLOCK_THREAD_CPUTIME_ID; with
// --wall-clock, std::chrono::steady_clock) around whole passes over the path (every span, every
// tick), so that on a shared machine the time other jobs run is not counted. A run repeats
// passes until it has timed at least --min-time-ms (50 ms); the figure is the best (lowest ns
// per setpoint) of --runs (5) runs, after one untimed warm-up pass. Runs are interleaved
// across methods (run 1 of each, then run 2 of each, ...) so that load elsewhere on the
// machine (which still costs caches and a shared core's execution units) cannot bias one
// method against another.
// Every output goes into a running Fletcher-style checksum so that no work can be optimised
// away; each method's checksum of its last timed pass must equal the checksum of its
// verified outputs, and the exact methods' must equal the exact one (the program prints a
// combined checksum at the end). Set-up (make_tick_cubic, prepare_span, double/float
// coefficients, the Eigen spline) is outside the timed region except in "push + tick".
// "ratio to double Horner" = (double Horner ns/setpoint) / (method ns/setpoint), from the
// same run: above 1 the method is faster than the baseline, below 1 slower.
//
// Exactness: the exact setpoints are round(Q(k) / D) computed here independently with
// __int128 (Q(k) = a k^3 + b n k^2 + c n^2 k + d n^3, D = 6 n^3, halves up). Integer Horner
// must equal them and all five exact FD variants must equal integer Horner bit for bit; the
// Eigen outputs must be within 1 LSB. Any violation prints what failed and exits with 1.
// "max error" is max |output - exact setpoint| in LSB over both axes and every tick;
// "pre-rounding error" is max |value before rounding - exact rational value| in LSB.
//
// Usage: bench_eval [--quick] [--ticks-per-span N]... [--markdown] [--runs R]
//                   [--min-time-ms T] [--wall-clock]
#include <algorithm>
#include <array>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <functional>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <unsupported/Eigen/Splines>
#include <vector>

#include "pathstream/basis.hpp"
#include "pathstream/forward_difference.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"
#include "pathstream/units.hpp"

#ifndef PATHSTREAM_BENCH_BUILD_TYPE
#define PATHSTREAM_BENCH_BUILD_TYPE "unknown"
#endif

namespace {

using pathstream::Lsb;
using pathstream::Status;
using i128 = __int128;

constexpr unsigned kAxes = 2;
constexpr int kControlPoints = 420;   // 60 per petal
constexpr double kAmplitude = 1.0e6;  // LSB
constexpr double kCentre[kAxes] = {1.1e6, 1.05e6};
constexpr std::uint32_t kQueuedCapacity = 512;  // >= kControlPoints: a whole pass queued

// ---------------------------------------------------------------------------------------------
// The path

struct Path {
    std::uint32_t n = 0;                                  // ticks per span
    std::vector<std::array<std::int32_t, kAxes>> points;  // control points, LSB
    std::vector<pathstream::Span<kAxes>> spans;
    pathstream::SpanTiming timing;
    std::vector<std::array<pathstream::TickCubic, kAxes>> cubics;
    std::vector<pathstream::PreparedSpan<kAxes>> prepared;
    std::size_t setpoints() const { return spans.size() * n; }
};

bool build_path(std::uint32_t n, Path& path) {
    path.n = n;
    path.points.resize(kControlPoints);
    for (int j = 0; j < kControlPoints; ++j) {
        const double t = 2.0 * std::numbers::pi * j / kControlPoints;
        const double r = kAmplitude * (0.55 + 0.45 * std::cos(7.0 * t));
        path.points[static_cast<std::size_t>(j)] = {
            static_cast<std::int32_t>(std::lround(kCentre[0] + r * std::cos(t))),
            static_cast<std::int32_t>(std::lround(kCentre[1] + r * std::sin(t)))};
    }
    if (Status s = pathstream::make_span_timing(pathstream::Basis::kUniformBSpline, n, path.timing);
        s != Status::kOk) {
        std::fprintf(stderr, "bench_eval: n = %u: %s\n", n, pathstream::status_name(s));
        return false;
    }
    const std::size_t count = path.points.size();
    path.spans.resize(count);
    path.cubics.resize(count);
    path.prepared.resize(count);
    for (std::size_t i = 0; i < count; ++i) {
        pathstream::Span<kAxes>& span = path.spans[i];
        span.basis = pathstream::Basis::kUniformBSpline;
        span.ticks = n;
        span.tag = static_cast<std::uint32_t>(i + 1);
        for (unsigned a = 0; a < kAxes; ++a) {
            for (std::size_t c = 0; c < 4; ++c)
                span.control[a][c] = path.points[(i + c) % count][a];
            if (Status s = pathstream::make_tick_cubic(span.basis, span.control[a], path.timing,
                                                       path.cubics[i][a]);
                s != Status::kOk) {
                std::fprintf(stderr, "bench_eval: span %zu axis %u: %s\n", i, a,
                             pathstream::status_name(s));
                return false;
            }
        }
        if (Status s = pathstream::prepare_span(span, path.prepared[i]); s != Status::kOk) {
            std::fprintf(stderr, "bench_eval: prepare span %zu: %s\n", i,
                         pathstream::status_name(s));
            return false;
        }
    }
    return true;
}

// ---------------------------------------------------------------------------------------------
// Sinks: every kernel hands each setpoint (and, for the floating-point methods, the value
// before rounding) to a sink taken by value and returned, so the timed loop keeps it in
// registers. Checksum is what the timed passes use; Verifier (below) is the verification pass.

struct Checksum {
    std::uint64_t s1 = 0, s2 = 0;
    void operator()(Lsb x, Lsb y) {
        s1 += static_cast<std::uint32_t>(x);
        s2 += s1;
        s1 += static_cast<std::uint32_t>(y);
        s2 += s1;
    }
    void operator()(Lsb x, Lsb y, double, double) { (*this)(x, y); }
    std::uint64_t value() const { return (s2 * 0x9E3779B97F4A7C15ull) ^ s1; }
};

inline Lsb round_lsb(double v) {
    return static_cast<Lsb>(std::floor(v + 0.5));
}
inline Lsb round_lsb(float v) {
    return static_cast<Lsb>(std::floor(v + 0.5f));
}

// ---------------------------------------------------------------------------------------------
// Kernels: one pass over the whole path each.

using QueuedStream = pathstream::SetpointStream<kAxes, kQueuedCapacity>;
using FedStream = pathstream::SetpointStream<kAxes, 4>;

/// Ticks `count` setpoints out of a stream whose spans are already queued.
template <class Sink>
Sink stream_ticks(QueuedStream& stream, std::size_t count, Sink sink, std::size_t& idle) {
    Lsb out[kAxes];
    std::size_t idle_ticks = 0;
    for (std::size_t t = 0; t < count; ++t) {
        idle_ticks += stream.tick(out) == pathstream::TickState::kIdle ? 1u : 0u;
        sink(out[0], out[1]);
    }
    idle += idle_ticks;
    return sink;
}

/// Queues up to the stream's capacity of spans starting at `first`; returns how many.
std::size_t queue_spans(const Path& path, QueuedStream& stream, std::size_t first, bool& ok) {
    std::size_t pushed = 0;
    while (first + pushed < path.spans.size() && stream.free_slots() > 0) {
        ok &= stream.push(path.spans[first + pushed]) == Status::kOk;
        ++pushed;
    }
    return pushed;
}

/// Producer and consumer interleaved: one span pushed (prepare_span) per n ticks.
template <class Sink>
Sink stream_push_and_tick(const Path& path, FedStream& stream, Sink sink, bool& ok) {
    Lsb out[kAxes];
    const std::size_t count = path.spans.size();
    bool pushed_ok = stream.push(path.spans[0]) == Status::kOk;
    std::size_t idle = 0;
    for (std::size_t i = 0; i < count; ++i) {
        if (i + 1 < count) pushed_ok &= stream.push(path.spans[i + 1]) == Status::kOk;
        for (std::uint32_t k = 0; k < path.n; ++k) {
            idle += stream.tick(out) == pathstream::TickState::kIdle ? 1u : 0u;
            sink(out[0], out[1]);
        }
    }
    ok &= pushed_ok && idle == 0;
    return sink;
}

template <class Word, class Sink>
Sink raw_steps(const Path& path, Sink sink) {
    Lsb out[kAxes];
    for (const pathstream::PreparedSpan<kAxes>& span : path.prepared) {
        pathstream::DifferenceState<Word> state[kAxes];
        if constexpr (sizeof(Word) == 4) {
            std::memcpy(state, span.narrow, sizeof state);
        } else {
            std::memcpy(state, span.wide_state, sizeof state);
        }
        const Word bias = static_cast<Word>(span.bias);
        for (std::uint32_t k = 0; k < span.ticks; ++k) {
            pathstream::emit_and_step(state, out, bias);
            sink(out[0], out[1]);
        }
    }
    return sink;
}

/// Setpoints per call of the batch kernels below: the buffer (2 KiB for 2 axes) stays in L1.
constexpr std::uint32_t kBatchTicks = 256;

/// The like-for-like row: prepared spans (as double Horner gets its coefficients ready), each
/// stepped by emit_span_ticks into a buffer of up to kBatchTicks setpoints, which the sink
/// then reads back; every setpoint is written to memory and read again, work the baseline,
/// which hands its values to the sink in registers, does not do.
template <class Word, class Sink>
Sink span_ticks(const Path& path, Sink sink) {
    Lsb out[kBatchTicks][kAxes];
    for (const pathstream::PreparedSpan<kAxes>& span : path.prepared) {
        pathstream::DifferenceState<Word> state[kAxes];
        if constexpr (sizeof(Word) == 4) {
            std::memcpy(state, span.narrow, sizeof state);
        } else {
            std::memcpy(state, span.wide_state, sizeof state);
        }
        const Word bias = static_cast<Word>(span.bias);
        for (std::uint32_t k = 0; k < span.ticks; k += kBatchTicks) {
            const std::uint32_t count = std::min(kBatchTicks, span.ticks - k);
            pathstream::emit_span_ticks(state, out, count, bias);
            for (std::uint32_t i = 0; i < count; ++i) sink(out[i][0], out[i][1]);
        }
    }
    return sink;
}

/// SetpointStream::tick_many over spans already queued, kBatchTicks setpoints per call.
template <class Sink>
Sink stream_tick_many(QueuedStream& stream, std::size_t count, Sink sink, std::size_t& idle) {
    Lsb out[kBatchTicks][kAxes];
    std::size_t idle_ticks = 0;
    for (std::size_t t = 0; t < count; t += kBatchTicks) {
        const auto batch =
            static_cast<std::uint32_t>(std::min<std::size_t>(kBatchTicks, count - t));
        idle_ticks += stream.tick_many(out, batch);
        for (std::uint32_t i = 0; i < batch; ++i) sink(out[i][0], out[i][1]);
    }
    idle += idle_ticks;
    return sink;
}

template <class Sink>
Sink integer_horner(const Path& path, Sink sink, bool& ok) {
    bool all_ok = true;
    for (const auto& cubic : path.cubics) {
        for (std::uint32_t k = 0; k < path.n; ++k) {
            Lsb x = 0, y = 0;
            all_ok &= pathstream::evaluate_at(cubic[0], path.timing, k, x) == Status::kOk;
            all_ok &= pathstream::evaluate_at(cubic[1], path.timing, k, y) == Status::kOk;
            sink(x, y);
        }
    }
    ok &= all_ok;
    return sink;
}

/// Per span and axis: the cubic's u-domain coefficients in double, highest power first.
using DoubleCoefficients = std::array<std::array<double, 4>, kAxes>;

std::vector<DoubleCoefficients> double_coefficients(const Path& path) {
    std::vector<DoubleCoefficients> out(path.cubics.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        for (unsigned a = 0; a < kAxes; ++a) {
            const pathstream::TickCubic& c = path.cubics[i][a];
            out[i][a] = {static_cast<double>(c.a) / 6.0, static_cast<double>(c.b) / 6.0,
                         static_cast<double>(c.c) / 6.0, static_cast<double>(c.d) / 6.0};
        }
    }
    return out;
}

template <class Sink>
Sink double_horner(const Path& path, const std::vector<DoubleCoefficients>& coef, Sink sink) {
    const double inv_n = 1.0 / path.n;
    for (const DoubleCoefficients& c : coef) {
        for (std::uint32_t k = 0; k < path.n; ++k) {
            const double u = k * inv_n;
            const double x = ((c[0][0] * u + c[0][1]) * u + c[0][2]) * u + c[0][3];
            const double y = ((c[1][0] * u + c[1][1]) * u + c[1][2]) * u + c[1][3];
            sink(round_lsb(x), round_lsb(y), x, y);
        }
    }
    return sink;
}

/// Per span and axis: float32 forward-differencing start (position and three differences).
using FloatStart = std::array<std::array<float, 4>, kAxes>;

std::vector<FloatStart> float_starts(const Path& path,
                                     const std::vector<DoubleCoefficients>& coef) {
    const double h = 1.0 / path.n;
    std::vector<FloatStart> out(coef.size());
    for (std::size_t i = 0; i < out.size(); ++i) {
        for (unsigned a = 0; a < kAxes; ++a) {
            const auto& c = coef[i][a];  // p(u) = c0 u^3 + c1 u^2 + c2 u + c3
            out[i][a] = {static_cast<float>(c[3]),
                         static_cast<float>(c[0] * h * h * h + c[1] * h * h + c[2] * h),
                         static_cast<float>(6.0 * c[0] * h * h * h + 2.0 * c[1] * h * h),
                         static_cast<float>(6.0 * c[0] * h * h * h)};
        }
    }
    return out;
}

template <class Sink>
Sink float_fd(const Path& path, const std::vector<FloatStart>& starts, Sink sink) {
    for (const FloatStart& s : starts) {
        float px = s[0][0], dx1 = s[0][1], dx2 = s[0][2];
        const float dx3 = s[0][3];
        float py = s[1][0], dy1 = s[1][1], dy2 = s[1][2];
        const float dy3 = s[1][3];
        for (std::uint32_t k = 0; k < path.n; ++k) {
            sink(round_lsb(px), round_lsb(py), px, py);
            px += dx1;
            dx1 += dx2;
            dx2 += dx3;
            py += dy1;
            dy1 += dy2;
            dy2 += dy3;
        }
    }
    return sink;
}

using EigenSpline = Eigen::Spline<double, 2, 3>;

EigenSpline eigen_spline(const Path& path) {
    const Eigen::Index count = static_cast<Eigen::Index>(path.points.size());
    EigenSpline::KnotVectorType knots(count + 7);
    for (Eigen::Index j = 0; j < knots.size(); ++j) knots(j) = static_cast<double>(j);
    EigenSpline::ControlPointVectorType ctrls(2, count + 3);
    for (Eigen::Index j = 0; j < count + 3; ++j) {
        const auto& p = path.points[static_cast<std::size_t>(j % count)];
        ctrls(0, j) = p[0];
        ctrls(1, j) = p[1];
    }
    return EigenSpline(knots, ctrls);
}

template <class Sink>
Sink eigen_eval(const Path& path, const EigenSpline& spline, Sink sink) {
    const double inv_n = 1.0 / path.n;
    const std::size_t count = path.spans.size();
    for (std::size_t i = 0; i < count; ++i) {
        const double base = static_cast<double>(i + 3);
        for (std::uint32_t k = 0; k < path.n; ++k) {
            const EigenSpline::PointType p = spline(base + k * inv_n);
            sink(round_lsb(p(0)), round_lsb(p(1)), p(0), p(1));
        }
    }
    return sink;
}

// ---------------------------------------------------------------------------------------------
// The independent exact reference (__int128), and comparison against it.

struct Accuracy {
    std::int64_t max_error = 0;      // LSB, rounded outputs
    std::size_t mismatches = 0;      // setpoint values (per axis) differing from the exact ones
    std::size_t tie_mismatches = 0;  // ... of which the exact value is a tie (x.5 exactly)
    double max_raw_error = -1.0;     // LSB before rounding; < 0: exact integer method
};

/// The exact value Q/D of one axis at one tick, as floor, fraction and rounded setpoint.
struct ExactValue {
    Lsb setpoint;  // round(Q/D), halves up
    Lsb floor_q;   // floor(Q/D)
    double frac;   // (Q - D floor(Q/D)) / D, in [0, 1)
};

/// Checks a method's outputs as they come, against the exact values computed here from the
/// control points alone (B-spline coefficients written out, __int128 arithmetic): nothing of
/// the core's arithmetic is reused. Nothing is stored, so any n fits in memory.
struct VerifyState {
    const Path* path = nullptr;
    std::size_t span = 0;
    std::uint32_t k = 0;
    std::size_t extra = 0;  // outputs beyond the path's last setpoint (a kernel bug)
    i128 coef[kAxes][4] = {};
    Accuracy accuracy;
    Checksum checksum;

    explicit VerifyState(const Path& p) : path(&p) { load_span(); }

    void load_span() {
        if (span >= path->spans.size()) return;
        for (unsigned a = 0; a < kAxes; ++a) {
            const std::int32_t* c = path->spans[span].control[a];
            const i128 p0 = c[0], p1 = c[1], p2 = c[2], p3 = c[3];
            coef[a][0] = -p0 + 3 * p1 - 3 * p2 + p3;  // times 6: u^3
            coef[a][1] = 3 * p0 - 6 * p1 + 3 * p2;    // u^2
            coef[a][2] = -3 * p0 + 3 * p2;            // u
            coef[a][3] = p0 + 4 * p1 + p2;            // 1
        }
    }

    ExactValue exact(unsigned axis) const {
        const i128 n = path->n, kk = k;
        const i128 den = 6 * n * n * n;
        const i128* c = coef[axis];
        const i128 q_num = ((c[0] * kk + c[1] * n) * kk + c[2] * n * n) * kk + c[3] * n * n * n;
        // floor(Q/D): a double estimate (off by at most one here), then corrected exactly.
        i128 q =
            static_cast<i128>(std::floor(static_cast<double>(q_num) / static_cast<double>(den)));
        i128 r = q_num - q * den;
        while (r < 0) {
            --q;
            r += den;
        }
        while (r >= den) {
            ++q;
            r -= den;
        }
        return ExactValue{static_cast<Lsb>(q + (2 * r >= den ? 1 : 0)), static_cast<Lsb>(q),
                          static_cast<double>(r) / static_cast<double>(den)};
    }

    void check(const Lsb (&out)[kAxes], const double* raw) {
        if (span >= path->spans.size()) {
            ++extra;
            return;
        }
        for (unsigned a = 0; a < kAxes; ++a) {
            const ExactValue e = exact(a);
            const std::int64_t err = std::llabs(std::int64_t{out[a]} - e.setpoint);
            accuracy.max_error = std::max(accuracy.max_error, err);
            accuracy.mismatches += err != 0 ? 1u : 0u;
            accuracy.tie_mismatches += err != 0 && e.frac == 0.5 ? 1u : 0u;
            if (raw != nullptr) {
                const double raw_err = std::fabs((raw[a] - e.floor_q) - e.frac);
                accuracy.max_raw_error = std::max(accuracy.max_raw_error, raw_err);
            }
        }
        checksum(out[0], out[1]);
        if (++k == path->n) {
            k = 0;
            ++span;
            load_span();
        }
    }

    /// Every setpoint of the path seen, and no more.
    bool complete() const { return span == path->spans.size() && k == 0 && extra == 0; }
};

struct Verifier {
    VerifyState* state;
    void operator()(Lsb x, Lsb y) {
        const Lsb out[kAxes] = {x, y};
        state->check(out, nullptr);
    }
    void operator()(Lsb x, Lsb y, double vx, double vy) {
        const Lsb out[kAxes] = {x, y};
        const double raw[kAxes] = {vx, vy};
        state->check(out, raw);
    }
};

// ---------------------------------------------------------------------------------------------
// Timing

struct Config {
    bool quick = false;
    bool markdown = false;
    int runs = 5;
    double min_time_ms = 50.0;
    bool wall_clock = false;
    std::vector<std::uint32_t> ticks_per_span;
};

/// What every timed region is measured with: by default the calling thread's CPU time
/// (CLOCK_THREAD_CPUTIME_ID), so that time the scheduler gives other jobs on a shared machine
/// is not charged to whichever method happened to be running; --wall-clock switches to
/// std::chrono::steady_clock. Nanoseconds either way.
struct Clock {
    using time_point = std::int64_t;
    static inline bool wall = false;
    static time_point now() {
        if (wall) {
            return std::chrono::duration_cast<std::chrono::nanoseconds>(
                       std::chrono::steady_clock::now().time_since_epoch())
                .count();
        }
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return std::int64_t{ts.tv_sec} * 1000000000 + ts.tv_nsec;
    }
};

double elapsed_ns(Clock::time_point t0, Clock::time_point t1) {
    return static_cast<double>(t1 - t0);
}

struct PassResult {
    double timed_ns;
    std::uint64_t checksum;
};

struct Timing {
    double ns_per_setpoint = 0.0;
    std::uint64_t checksum = 0;  // of the last timed pass
};

/// One run of one method: repeats `pass` until it has timed >= cfg.min_time_ms; returns ns
/// per setpoint and keeps the last pass's checksum.
double run_once(const Config& cfg, std::size_t setpoints_per_pass,
                const std::function<PassResult()>& pass, std::uint64_t& checksum) {
    double timed = 0.0;
    std::size_t passes = 0;
    do {
        const PassResult r = pass();
        timed += r.timed_ns;
        checksum = r.checksum;
        ++passes;
    } while (timed < cfg.min_time_ms * 1e6);
    return timed / static_cast<double>(passes * setpoints_per_pass);
}

/// Best of cfg.runs runs per method. The runs are interleaved (run 1 of every method, then
/// run 2 of every method, ...) so that a burst of load elsewhere on the machine slows one run
/// of every method rather than all runs of one, which keeps the ratios honest.
std::vector<Timing> measure_all(const Config& cfg, std::size_t setpoints_per_pass,
                                const std::vector<std::function<PassResult()>>& passes) {
    std::vector<Timing> t(passes.size());
    for (Timing& each : t) each.ns_per_setpoint = std::numeric_limits<double>::infinity();
    if (!cfg.quick) {
        for (std::size_t m = 0; m < passes.size(); ++m) t[m].checksum = passes[m]().checksum;
    }
    for (int run = 0; run < cfg.runs; ++run) {
        for (std::size_t m = 0; m < passes.size(); ++m) {
            const double ns = run_once(cfg, setpoints_per_pass, passes[m], t[m].checksum);
            t[m].ns_per_setpoint = std::min(t[m].ns_per_setpoint, ns);
        }
    }
    return t;
}

/// Times a pass that is timed as a whole.
template <class Body>
PassResult timed_pass(Body body) {
    const Clock::time_point t0 = Clock::now();
    const Checksum c = body();
    const Clock::time_point t1 = Clock::now();
    return PassResult{elapsed_ns(t0, t1), c.value()};
}

// ---------------------------------------------------------------------------------------------
// One case (one n): verify every method, time every method, print the table.

struct Row {
    std::string method;
    Timing timing;
    Accuracy accuracy;
    std::uint64_t verified_checksum = 0;
};

std::string format_rate(double per_second) {
    char buf[32];
    if (per_second >= 1e9)
        std::snprintf(buf, sizeof buf, "%.2f G", per_second / 1e9);
    else if (per_second >= 1e6)
        std::snprintf(buf, sizeof buf, "%.1f M", per_second / 1e6);
    else
        std::snprintf(buf, sizeof buf, "%.1f k", per_second / 1e3);
    return buf;
}

/// `<` and `>` as HTML entities, so that "Spline<double,2,3>" is not taken for a tag.
std::string markdown_escape(const std::string& text) {
    std::string out;
    for (char ch : text) {
        if (ch == '<')
            out += "&lt;";
        else if (ch == '>')
            out += "&gt;";
        else
            out += ch;
    }
    return out;
}

std::string format_fixed(double v, int decimals) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
    return buf;
}

std::string format_raw_error(const Accuracy& a) {
    if (a.max_raw_error < 0) return "exact";
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1e", a.max_raw_error);
    return buf;
}

std::string format_error(const Accuracy& a, std::size_t values) {
    char buf[64];
    if (a.mismatches == 0)
        std::snprintf(buf, sizeof buf, "%" PRId64, a.max_error);
    else
        std::snprintf(buf, sizeof buf, "%" PRId64 " (%zu of %zu off)", a.max_error, a.mismatches,
                      values);
    return buf;
}

void print_table(const Config& cfg, const std::vector<Row>& rows, double baseline_ns,
                 std::size_t values) {
    const char* headers[6] = {"method",        "setpoints/s",
                              "ns/setpoint",   "ratio to double Horner",
                              "max error LSB", "pre-rounding error LSB"};
    std::vector<std::array<std::string, 6>> cells;
    for (const Row& r : rows) {
        const double ns = r.timing.ns_per_setpoint;
        cells.push_back({r.method, format_rate(1e9 / ns), format_fixed(ns, 2),
                         format_fixed(baseline_ns / ns, 2) + "x", format_error(r.accuracy, values),
                         format_raw_error(r.accuracy)});
    }
    if (cfg.markdown) {
        std::printf("| %s | %s | %s | %s | %s | %s |\n", headers[0], headers[1], headers[2],
                    headers[3], headers[4], headers[5]);
        std::printf("|---|---:|---:|---:|---:|---:|\n");
        for (const auto& c : cells) {
            std::printf("| %s | %s | %s | %s | %s | %s |\n", markdown_escape(c[0]).c_str(),
                        c[1].c_str(), c[2].c_str(), c[3].c_str(), c[4].c_str(), c[5].c_str());
        }
        return;
    }
    std::size_t width[6];
    for (int i = 0; i < 6; ++i) {
        width[i] = std::strlen(headers[i]);
        for (const auto& c : cells)
            width[i] = std::max(width[i], c[static_cast<std::size_t>(i)].size());
    }
    auto line = [&](const std::array<std::string, 6>& c) {
        std::printf("  %-*s", static_cast<int>(width[0]), c[0].c_str());
        for (int i = 1; i < 6; ++i) {
            std::printf(" | %*s", static_cast<int>(width[i]),
                        c[static_cast<std::size_t>(i)].c_str());
        }
        std::printf("\n");
    };
    line({headers[0], headers[1], headers[2], headers[3], headers[4], headers[5]});
    std::string rule = "  ";
    for (int i = 0; i < 6; ++i) rule += std::string(width[i] + (i == 0 ? 0 : 3), '-');
    std::printf("%s\n", rule.c_str());
    for (const auto& c : cells) line(c);
}

/// Returns false on any exactness failure (already reported on stderr).
bool run_case(const Config& cfg, std::uint32_t n, std::uint64_t& grand_checksum) {
    Path path;
    if (!build_path(n, path)) return false;
    const std::size_t setpoints = path.setpoints();
    const std::size_t values = setpoints * kAxes;
    const bool narrow = pathstream::is_narrow(path.timing);
    bool ok = true;
    auto fail = [&](const std::string& what) {
        std::fprintf(stderr, "bench_eval: n = %u: FAILED: %s\n", n, what.c_str());
        ok = false;
    };

    // Inputs of the floating-point methods (set-up, never timed).
    const std::vector<DoubleCoefficients> coef = double_coefficients(path);
    const std::vector<FloatStart> starts = float_starts(path, coef);
    const EigenSpline spline = eigen_spline(path);
    // Both streams start where the path starts (span 0's tick-0 value): push() accepts only a
    // continuous chain from the stream's start position. The path is closed (span N-1 ends
    // where span 0 starts), so every pass continues the chain of the one before.
    Lsb start[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) {
        if (pathstream::evaluate_at(path.cubics[0][a], path.timing, 0, start[a]) != Status::kOk) {
            fail("evaluate_at(0) of span 0 failed");
            return false;
        }
    }
    auto queued = std::make_unique<QueuedStream>(start);
    auto batched = std::make_unique<QueuedStream>(start);
    auto fed = std::make_unique<FedStream>(start);

    // Verification pass: every method's outputs checked against the exact values as they come.
    std::vector<Row> rows;
    rows.reserve(9);
    auto record = [&](const std::string& method, auto&& body) {
        VerifyState state(path);
        body(Verifier{&state});
        if (!state.complete()) fail(method + ": did not produce exactly one setpoint per tick");
        Row row;
        row.method = method;
        row.accuracy = state.accuracy;
        row.verified_checksum = state.checksum.value();
        rows.push_back(row);
    };
    enum RowId {
        kStreamTick,
        kStreamPush,
        kRawStep,
        kStreamBatch,
        kSpanTicks,
        kIntHorner,
        kDoubleHorner,
        kFloatFd,
        kEigen
    };

    record("exact FD: SetpointStream::tick (spans queued)", [&](Verifier r) {
        std::size_t idle = 0;
        bool pushed = true;
        for (std::size_t first = 0; first < path.spans.size();) {
            const std::size_t count = queue_spans(path, *queued, first, pushed);
            r = stream_ticks(*queued, count * n, r, idle);
            first += count;
        }
        if (!pushed || idle != 0) fail("SetpointStream (queued): push failed or went idle");
    });
    record("exact FD: SetpointStream push + tick", [&](Verifier r) {
        bool good = true;
        stream_push_and_tick(path, *fed, r, good);
        if (!good) fail("SetpointStream (fed): push failed or went idle");
    });
    record(std::string("exact FD: raw emit_and_step (") + (narrow ? "32" : "64") + "-bit)",
           [&](Verifier r) {
               if (narrow)
                   raw_steps<std::uint32_t>(path, r);
               else
                   raw_steps<std::uint64_t>(path, r);
           });
    record("exact FD: SetpointStream::tick_many (spans queued)", [&](Verifier r) {
        std::size_t idle = 0;
        bool pushed = true;
        for (std::size_t first = 0; first < path.spans.size();) {
            const std::size_t count = queue_spans(path, *batched, first, pushed);
            r = stream_tick_many(*batched, count * n, r, idle);
            first += count;
        }
        if (!pushed || idle != 0) fail("SetpointStream (tick_many): push failed or went idle");
    });
    record(std::string("exact FD: emit_span_ticks (") + (narrow ? "32" : "64") +
               "-bit), like-for-like",
           [&](Verifier r) {
               if (narrow)
                   span_ticks<std::uint32_t>(path, r);
               else
                   span_ticks<std::uint64_t>(path, r);
           });
    record("integer Horner: evaluate_at (128-bit)", [&](Verifier r) {
        bool good = true;
        integer_horner(path, r, good);
        if (!good) fail("evaluate_at returned an error");
    });
    record("double Horner (baseline)", [&](Verifier r) { double_horner(path, coef, r); });
    record("float32 forward differencing", [&](Verifier r) { float_fd(path, starts, r); });
    record("Eigen::Spline<double,2,3> (de Boor)", [&](Verifier r) { eigen_eval(path, spline, r); });

    // The checks that make the benchmark meaningful.
    if (rows[kIntHorner].accuracy.mismatches != 0) {
        fail("integer Horner (evaluate_at) differs from the independent __int128 reference in " +
             std::to_string(rows[kIntHorner].accuracy.mismatches) + " values");
    }
    for (RowId id : {kStreamTick, kStreamPush, kRawStep, kStreamBatch, kSpanTicks}) {
        if (rows[id].verified_checksum != rows[kIntHorner].verified_checksum ||
            rows[id].accuracy.mismatches != rows[kIntHorner].accuracy.mismatches ||
            rows[id].accuracy.max_error != 0) {
            fail(rows[id].method + " is not bit-identical to integer Horner (" +
                 std::to_string(rows[id].accuracy.mismatches) + " values off, max " +
                 std::to_string(rows[id].accuracy.max_error) + " LSB)");
        }
    }
    if (rows[kEigen].accuracy.max_error > 1) {
        fail("Eigen::Spline is more than 1 LSB off the exact setpoints (max " +
             std::to_string(rows[kEigen].accuracy.max_error) + " LSB)");
    }

    // Timed passes, in the order of the rows.
    std::vector<std::function<PassResult()>> passes;
    passes.push_back([&] {
        Checksum c;
        double timed = 0.0;
        std::size_t idle = 0;
        bool pushed = true;
        for (std::size_t first = 0; first < path.spans.size();) {
            const std::size_t count = queue_spans(path, *queued, first, pushed);  // untimed
            const Clock::time_point t0 = Clock::now();
            c = stream_ticks(*queued, count * n, c, idle);
            timed += elapsed_ns(t0, Clock::now());
            first += count;
        }
        if (!pushed || idle != 0) fail("SetpointStream (queued) misbehaved in a timed pass");
        return PassResult{timed, c.value()};
    });
    passes.push_back([&] {
        bool good = true;
        const PassResult r =
            timed_pass([&] { return stream_push_and_tick(path, *fed, Checksum{}, good); });
        if (!good) fail("SetpointStream (fed) misbehaved in a timed pass");
        return r;
    });
    passes.push_back([&] {
        return timed_pass([&] {
            return narrow ? raw_steps<std::uint32_t>(path, Checksum{})
                          : raw_steps<std::uint64_t>(path, Checksum{});
        });
    });
    passes.push_back([&] {
        Checksum c;
        double timed = 0.0;
        std::size_t idle = 0;
        bool pushed = true;
        for (std::size_t first = 0; first < path.spans.size();) {
            const std::size_t count = queue_spans(path, *batched, first, pushed);  // untimed
            const Clock::time_point t0 = Clock::now();
            c = stream_tick_many(*batched, count * n, c, idle);
            timed += elapsed_ns(t0, Clock::now());
            first += count;
        }
        if (!pushed || idle != 0) fail("SetpointStream (tick_many) misbehaved in a timed pass");
        return PassResult{timed, c.value()};
    });
    passes.push_back([&] {
        return timed_pass([&] {
            return narrow ? span_ticks<std::uint32_t>(path, Checksum{})
                          : span_ticks<std::uint64_t>(path, Checksum{});
        });
    });
    passes.push_back([&] {
        bool good = true;
        const PassResult r = timed_pass([&] { return integer_horner(path, Checksum{}, good); });
        if (!good) fail("evaluate_at returned an error in a timed pass");
        return r;
    });
    passes.push_back(
        [&] { return timed_pass([&] { return double_horner(path, coef, Checksum{}); }); });
    passes.push_back(
        [&] { return timed_pass([&] { return float_fd(path, starts, Checksum{}); }); });
    passes.push_back(
        [&] { return timed_pass([&] { return eigen_eval(path, spline, Checksum{}); }); });

    const std::vector<Timing> timings = measure_all(cfg, setpoints, passes);
    for (std::size_t m = 0; m < rows.size(); ++m) rows[m].timing = timings[m];

    for (const Row& r : rows) {
        if (r.timing.checksum != r.verified_checksum) {
            fail(r.method + ": timed pass checksum differs from the verified outputs");
        }
        grand_checksum = grand_checksum * 1099511628211ull + r.timing.checksum;
    }

    // Report.
    const double baseline_ns = rows[kDoubleHorner].timing.ns_per_setpoint;
    const char* heading = cfg.markdown ? "### " : "";
    std::printf("\n%sn = %u ticks per span (%s: D = 6 n^3 = %" PRIu64 ", %s-bit remainders)\n\n",
                heading, n, narrow ? "narrow" : "wide", path.timing.denominator,
                narrow ? "32" : "64");
    print_table(cfg, rows, baseline_ns, values);
    const char* indent = cfg.markdown ? "" : "  ";
    const char* end = cfg.markdown ? "  \n" : "\n";  // Markdown hard line break
    std::printf("\n%s%zu spans, %zu setpoints per pass (%zu axis values)%s", indent,
                path.spans.size(), setpoints, values, end);
    bool fd_identical = true;
    for (RowId id : {kStreamTick, kStreamPush, kRawStep, kStreamBatch, kSpanTicks}) {
        fd_identical &= rows[id].accuracy.mismatches == 0 &&
                        rows[id].verified_checksum == rows[kIntHorner].verified_checksum;
    }
    std::printf(
        "%schecks: exact FD == integer Horner bit for bit: %s; integer Horner == "
        "independent __int128 reference: %s; Eigen within 1 LSB: %s%s",
        indent, fd_identical ? "yes" : "NO",
        rows[kIntHorner].accuracy.mismatches == 0 ? "yes" : "NO",
        rows[kEigen].accuracy.max_error <= 1 ? "yes" : "NO", end);
    for (RowId id : {kDoubleHorner, kFloatFd, kEigen}) {
        const Accuracy& a = rows[id].accuracy;
        if (a.tie_mismatches == 0) continue;
        std::printf("%s%s: %zu of its %zu wrong values are exact ties (exact value x.5 LSB)%s",
                    indent,
                    (cfg.markdown ? markdown_escape(rows[id].method) : rows[id].method).c_str(),
                    a.tie_mismatches, a.mismatches, end);
    }
    return ok;
}

bool parse_uint(const char* s, long long lo, long long hi, long long& out) {
    char* end = nullptr;
    const long long v = std::strtoll(s, &end, 10);
    if (end == s || *end != '\0' || v < lo || v > hi) return false;
    out = v;
    return true;
}

void usage(std::FILE* f) {
    std::fprintf(f,
                 "usage: bench_eval [--quick] [--ticks-per-span N]... [--markdown] [--runs R] "
                 "[--min-time-ms T] [--wall-clock]\n"
                 "  --quick             one timed pass per method (CI smoke; checks still run)\n"
                 "  --ticks-per-span N  n of every span, 1..%u (repeatable; default 64 and 4096)\n"
                 "  --markdown          print the tables as Markdown\n"
                 "  --runs R            runs per method, best taken (default 5)\n"
                 "  --min-time-ms T     timed work per run (default 50)\n"
                 "  --wall-clock        time with steady_clock instead of the thread's CPU time\n"
                 "Exit status: 0, 1 on an exactness mismatch, 2 on a usage error.\n",
                 pathstream::kMaxSpanTicks);
}

}  // namespace

int main(int argc, char** argv) {
    Config cfg;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        long long v = 0;
        if (arg == "--quick") {
            cfg.quick = true;
        } else if (arg == "--markdown") {
            cfg.markdown = true;
        } else if (arg == "--wall-clock") {
            cfg.wall_clock = true;
        } else if (arg == "--help" || arg == "-h") {
            usage(stdout);
            return 0;
        } else if (arg == "--ticks-per-span" && i + 1 < argc &&
                   parse_uint(argv[i + 1], 1, pathstream::kMaxSpanTicks, v)) {
            cfg.ticks_per_span.push_back(static_cast<std::uint32_t>(v));
            ++i;
        } else if (arg == "--runs" && i + 1 < argc && parse_uint(argv[i + 1], 1, 1000, v)) {
            cfg.runs = static_cast<int>(v);
            ++i;
        } else if (arg == "--min-time-ms" && i + 1 < argc &&
                   parse_uint(argv[i + 1], 0, 100000, v)) {
            cfg.min_time_ms = static_cast<double>(v);
            ++i;
        } else {
            std::fprintf(stderr, "bench_eval: bad argument '%s'\n", arg.c_str());
            usage(stderr);
            return 2;
        }
    }
    if (cfg.quick) {
        cfg.runs = 1;
        cfg.min_time_ms = 0.0;
    }
    if (cfg.ticks_per_span.empty()) cfg.ticks_per_span = {64, 4096};
    Clock::wall = cfg.wall_clock;

    std::printf(
        "%sbench_eval: closed uniform cubic B-spline, %d control points (7-petal rose, "
        "amplitude %.0f LSB), 2 axes; one setpoint = both axes at one tick\n",
        cfg.markdown ? "" : "", kControlPoints, kAmplitude);
    std::printf(
        "timing: %s, best of %d run(s) of >= %.0f ms timed work%s; ratio = "
        "double Horner ns / method ns (> 1: faster than the baseline); bench -O2, core "
        "library build type %s\n",
        cfg.wall_clock ? "steady_clock (wall time)" : "thread CPU time", cfg.runs, cfg.min_time_ms,
        cfg.quick ? " (--quick)" : " after a warm-up pass", PATHSTREAM_BENCH_BUILD_TYPE);

    bool ok = true;
    std::uint64_t checksum = 0;
    for (std::uint32_t n : cfg.ticks_per_span) ok &= run_case(cfg, n, checksum);
    std::printf("\nchecksum %016" PRIx64 "\n", checksum);
    if (!ok) {
        std::fprintf(stderr, "bench_eval: exactness check FAILED\n");
        return 1;
    }
    return 0;
}
