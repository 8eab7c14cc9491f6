// Geometric properties of the core's spans, checked as a black box against the independent
// exact reference (tests/core/reference.hpp) and against closed-form textbook identities:
//   - uniform B-spline spans sharing three points join C2, Catmull-Rom spans join C1, and the
//     setpoints emitted around a joint have no gap and no repeated tick;
//   - end points and end tangents of Catmull-Rom, Bezier and Hermite spans;
//   - B-spline and Bezier setpoints stay inside the per-axis hull of their points;
//   - adding an integer offset to every position shifts every setpoint by exactly that offset;
//   - spans just inside and just outside the 32-bit denominator limit are exact tick by tick.
//
// Per-span work is a handful of evaluate_at / start_differences calls (never every tick of a
// long span), so the default CI size (--spans 100000 under ASan) stays within a few seconds.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/property_settings.hpp"
#include "core/reference.hpp"
#include "pathstream/basis.hpp"
#include "pathstream/forward_difference.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "pathstream/tick_cubic.hpp"

using pathstream::Basis;
using pathstream::DifferenceState;
using pathstream::Lsb;
using pathstream::SetpointStream;
using pathstream::Span;
using pathstream::SpanTiming;
using pathstream::Status;
using pathstream::TickCubic;
using pathstream::TickState;
using pathstream::test::i128;
using pathstream::test::Rational;
using pathstream::test::reference_setpoint;
using pathstream::test::reference_value;
using pathstream::test::SpanGenerator;

namespace {

// ---- small helpers (local to this file) -------------------------------------------------

std::string str(i128 v) {
    if (v == 0) return "0";
    const bool negative = v < 0;
    unsigned __int128 m =
        negative ? -static_cast<unsigned __int128>(v) : static_cast<unsigned __int128>(v);
    std::string s;
    while (m != 0) {
        s.insert(s.begin(), static_cast<char>('0' + static_cast<int>(m % 10)));
        m /= 10;
    }
    return negative ? "-" + s : s;
}

std::string name(Status s) {
    return pathstream::status_name(s);
}

const char* basis_name(Basis b) {
    switch (b) {
        case Basis::kUniformBSpline:
            return "B-spline";
        case Basis::kCatmullRom:
            return "Catmull-Rom";
        case Basis::kBezier:
            return "Bezier";
        case Basis::kHermite:
            return "Hermite";
    }
    return "?";
}

template <std::size_t N>
std::string describe(Basis b, const std::int32_t (&p)[N], std::int64_t n) {
    std::ostringstream os;
    os << basis_name(b) << " n=" << n << " points {";
    for (std::size_t i = 0; i < N; ++i) os << (i ? ", " : "") << p[i];
    os << "}";
    return os.str();
}

/// Fails the test with `context` (evaluated only on failure) when `cond` is false. Keeps
/// Catch's per-assertion cost out of the hot loops.
#define EXPECT(cond, context)                                  \
    do {                                                       \
        if (!(cond)) FAIL(#cond << "  [" << (context) << "]"); \
    } while (0)

/// One axis of a span as the core builds it.
struct Axis {
    SpanTiming timing;
    TickCubic cubic;
};

Status build(Basis basis, const std::int32_t (&p)[4], std::uint32_t n, Axis& out) {
    if (const Status s = pathstream::make_span_timing(basis, n, out.timing); s != Status::kOk) {
        return s;
    }
    return pathstream::make_tick_cubic(basis, p, out.timing, out.cubic);
}

/// The core's setpoint at tick k (evaluate_at), which must succeed.
std::int64_t core_at(const Axis& a, std::uint32_t k) {
    Lsb v = 0;
    const Status s = pathstream::evaluate_at(a.cubic, a.timing, k, v);
    if (s != Status::kOk)
        FAIL("evaluate_at(" << k << ") of n=" << a.timing.ticks << ": " << name(s));
    return v;
}

/// The core's tick-0 value of `span` on every axis (make_span_timing, make_tick_cubic,
/// evaluate_at), where a stream must start for `span` to be its first span; or the span's
/// validation error.
template <unsigned Axes>
Status core_start(const Span<Axes>& span, Lsb (&start)[Axes]) {
    for (unsigned a = 0; a < Axes; ++a) {
        Axis axis;
        if (const Status s = build(span.basis, span.control[a], span.ticks, axis);
            s != Status::kOk) {
            return s;
        }
        start[a] = static_cast<Lsb>(core_at(axis, 0));
    }
    return Status::kOk;
}

/// Setpoints the core's forward differencer emits for ticks k0, k0+1, ..., k0+count-1
/// (started with start_differences at k0 and stepped; the width the span calls for).
template <typename Word>
void emit_from(const Axis& a, std::uint32_t k0, std::uint32_t count, std::int64_t* out) {
    DifferenceState<Word> state{};
    const Status s = pathstream::start_differences(a.cubic, a.timing, k0, state);
    if (s != Status::kOk) FAIL("start_differences(" << k0 << "): " << name(s));
    const auto bias = static_cast<Word>(pathstream::difference_bias(a.timing));
    for (std::uint32_t i = 0; i < count; ++i) {
        out[i] = state.position();
        state.step(bias);
    }
}
void emit(const Axis& a, std::uint32_t k0, std::uint32_t count, std::int64_t* out) {
    if (pathstream::is_narrow(a.timing)) {
        emit_from<std::uint32_t>(a, k0, count, out);
    } else {
        emit_from<std::uint64_t>(a, k0, count, out);
    }
}

/// x == y for two exact rationals whose denominators share a large common factor (here
/// always equal or small), without overflow: cross-multiply by the cofactors only.
bool same_value(const Rational& x, const Rational& y) {
    i128 a = x.denominator, b = y.denominator;
    while (b != 0) {
        const i128 t = a % b;
        a = b;
        b = t;
    }
    return x.numerator * (y.denominator / a) == y.numerator * (x.denominator / a);
}
std::string str(const Rational& r) {
    return str(r.numerator) + "/" + str(r.denominator);
}

/// Exact first and second derivative in u (u = k/n) of a span's curve at tick k0, from the
/// reference alone: Newton forward differences of the cubic at k0..k0+3 (the closed form is
/// a polynomial, so k0+j past the end is simply its extension).
struct Derivatives {
    Rational d1, d2;
};
Derivatives reference_derivatives(Basis b, const std::int32_t (&p)[4], std::int64_t n,
                                  std::int64_t k0) {
    i128 v[4];
    i128 den = 0;
    for (int j = 0; j < 4; ++j) {
        const Rational r = reference_value(b, p, n, k0 + j);
        v[j] = r.numerator;
        den = r.denominator;
    }
    const i128 f1 = v[1] - v[0];
    const i128 f2 = v[2] - 2 * v[1] + v[0];
    const i128 f3 = v[3] - 3 * v[2] + 3 * v[1] - v[0];
    // f'(k0) = f1 - f2/2 + f3/3 per tick; f''(k0) = f2 - f3 per tick^2.
    return Derivatives{Rational{(6 * f1 - 3 * f2 + 2 * f3) * n, 6 * den},
                       Rational{(f2 - f3) * n * n, den}};
}

/// Core's derivatives in u at u = 0 and u = 1, read from its documented tick cubic
/// (p(u) = (a u^3 + b u^2 + c u + d) / scale).
Rational core_d1(const Axis& a, Basis b, bool at_end) {
    const i128 s = pathstream::basis_matrix(b).scale;
    const TickCubic& c = a.cubic;
    return at_end ? Rational{3 * i128{c.a} + 2 * i128{c.b} + c.c, s} : Rational{c.c, s};
}
Rational core_d2(const Axis& a, Basis b, bool at_end) {
    const i128 s = pathstream::basis_matrix(b).scale;
    const TickCubic& c = a.cubic;
    return at_end ? Rational{6 * i128{c.a} + 2 * i128{c.b}, s} : Rational{2 * i128{c.b}, s};
}

/// `count` random positions in the style mix of SpanGenerator (anywhere, at the limits,
/// tiny, clustered), for points shared between consecutive spans.
void random_points(SpanGenerator& g, std::int32_t* p, int count,
                   std::int64_t limit = pathstream::kMaxPositionLsb) {
    const int style = static_cast<int>(g.uniform(0, 3));
    const std::int64_t center = g.uniform(-limit / 2, limit / 2);
    for (int i = 0; i < count; ++i) {
        std::int64_t v = 0;
        switch (style) {
            case 0:
                v = g.uniform(-limit, limit);
                break;
            case 1:
                v = (g.uniform(0, 1) ? limit : -limit) - g.uniform(-3, 3);
                break;
            case 2:
                v = g.uniform(-1000, 1000);
                break;
            default:
                v = center + g.uniform(-50000, 50000);
                break;
        }
        p[i] = static_cast<std::int32_t>(std::clamp(v, -limit, limit));
    }
}

/// Ticks of [0, n] at which the exact curve comes nearest its extremes: both ends and the
/// integers around the real critical points (found in long double, widened by +/-2 ticks so
/// rounding of the root cannot miss the integer extremum).
std::vector<std::uint32_t> extreme_ticks(Basis b, const std::int32_t (&p)[4], std::int64_t n) {
    long double v[4];
    for (int j = 0; j < 4; ++j)
        v[j] = static_cast<long double>(reference_value(b, p, n, j).numerator);
    const long double f1 = v[1] - v[0], f2 = v[2] - 2 * v[1] + v[0],
                      f3 = v[3] - 3 * v[2] + 3 * v[1] - v[0];
    // N'(k) = (f3/2) k^2 + (f2 - f3) k + (f1 - f2/2 + f3/3)
    const long double qa = f3 / 2, qb = f2 - f3, qc = f1 - f2 / 2 + f3 / 3;
    std::vector<long double> roots;
    if (qa == 0) {
        if (qb != 0) roots.push_back(-qc / qb);
    } else {
        const long double disc = qb * qb - 4 * qa * qc;
        if (disc >= 0) {
            const long double sq = std::sqrt(disc);
            const long double q = -0.5L * (qb + (qb >= 0 ? sq : -sq));
            roots.push_back(q / qa);
            if (q != 0) roots.push_back(qc / q);
        }
    }
    std::vector<std::uint32_t> ticks{0, static_cast<std::uint32_t>(n)};
    for (long double r : roots) {
        if (!(r > -3 && r < static_cast<long double>(n) + 3)) continue;
        const auto base = static_cast<std::int64_t>(std::floor(r));
        for (std::int64_t k = base - 2; k <= base + 3; ++k) {
            if (k >= 0 && k <= n) ticks.push_back(static_cast<std::uint32_t>(k));
        }
    }
    return ticks;
}

/// How many random spans a property runs per basis: the command line's size, divided by
/// `divisor` for properties that cost more per span (at least `floor_count`).
std::uint64_t spans_for(std::uint64_t divisor, std::uint64_t floor_count = 50) {
    return std::max<std::uint64_t>(floor_count, pathstream::test::g_spans_per_basis / divisor);
}

constexpr Basis kAllBases[] = {Basis::kUniformBSpline, Basis::kCatmullRom, Basis::kBezier,
                               Basis::kHermite};

}  // namespace

// ---- B-spline joints --------------------------------------------------------------------

TEST_CASE("B-spline spans sharing three points join C2, exactly and in the emitted setpoints",
          "[properties]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed);
    const std::uint64_t pairs = spans_for(1);
    const Basis b = Basis::kUniformBSpline;
    std::uint64_t accepted = 0;
    for (std::uint64_t i = 0; i < pairs; ++i) {
        std::int32_t pts[5];
        random_points(gen, pts, 5);
        const std::uint32_t n = gen.ticks();
        const std::int32_t p1[4] = {pts[0], pts[1], pts[2], pts[3]};
        const std::int32_t p2[4] = {pts[1], pts[2], pts[3], pts[4]};
        Axis s1, s2;
        if (build(b, p1, n, s1) != Status::kOk || build(b, p2, n, s2) != Status::kOk) continue;
        ++accepted;
        const auto ctx = [&] { return describe(b, pts, n); };

        // Exact curve: value, first and second derivative agree at the joint.
        const Rational end1 = reference_value(b, p1, n, n), start2 = reference_value(b, p2, n, 0);
        EXPECT(same_value(end1, start2), ctx() + " value " + str(end1) + " vs " + str(start2));
        const Derivatives e1 = reference_derivatives(b, p1, n, n);
        const Derivatives b2 = reference_derivatives(b, p2, n, 0);
        EXPECT(same_value(e1.d1, b2.d1), ctx() + " p' " + str(e1.d1) + " vs " + str(b2.d1));
        EXPECT(same_value(e1.d2, b2.d2), ctx() + " p'' " + str(e1.d2) + " vs " + str(b2.d2));
        // ... and equal the textbook values (P3-P1)/2 and P1 - 2 P2 + P3 at the joint.
        EXPECT(same_value(e1.d1, Rational{i128{pts[3]} - pts[1], 2}), ctx());
        EXPECT(same_value(e1.d2, Rational{i128{pts[1]} - 2 * i128{pts[2]} + pts[3], 1}), ctx());

        // The core's own cubics: same joint derivatives.
        EXPECT(same_value(core_d1(s1, b, true), core_d1(s2, b, false)), ctx());
        EXPECT(same_value(core_d2(s1, b, true), core_d2(s2, b, false)), ctx());
        EXPECT(same_value(core_d1(s1, b, true), e1.d1), ctx());
        EXPECT(same_value(core_d2(s1, b, true), e1.d2), ctx());

        // The core's emitted setpoints around the joint: span 1's last up-to-three ticks then
        // span 2's first ticks, as the stream would play them (n-3..n-1 | 0..2), plus span 1
        // stepped onto its tick n, which must be span 2's tick 0 (no gap, no repeat).
        const std::uint32_t before = std::min<std::uint32_t>(n, 3);
        const std::uint32_t after = std::min<std::uint32_t>(n, 3);
        std::int64_t tail[4], head[4];
        emit(s1, n - before, before + 1, tail);  // ticks n-before .. n
        emit(s2, 0, after, head);                // ticks 0 .. after-1
        EXPECT(tail[before] == head[0], ctx() + " stepped end " + std::to_string(tail[before]) +
                                            " vs next start " + std::to_string(head[0]));
        EXPECT(core_at(s1, n) == core_at(s2, 0), ctx());
        std::vector<std::int64_t> played, expected;
        for (std::uint32_t j = 0; j < before; ++j) {
            played.push_back(tail[j]);
            expected.push_back(reference_setpoint(b, p1, n, n - before + j));
        }
        for (std::uint32_t j = 0; j < after; ++j) {
            played.push_back(head[j]);
            expected.push_back(reference_setpoint(b, p2, n, j));
        }
        for (std::size_t j = 0; j < played.size(); ++j) {
            EXPECT(played[j] == expected[j], ctx() + " setpoint " + std::to_string(j));
        }
        // First and second differences across the joint (index `before` is span 2's tick 0).
        for (std::size_t j = 1; j < played.size(); ++j) {
            EXPECT(played[j] - played[j - 1] == expected[j] - expected[j - 1], ctx());
        }
        for (std::size_t j = 2; j < played.size(); ++j) {
            EXPECT(played[j] - 2 * played[j - 1] + played[j - 2] ==
                       expected[j] - 2 * expected[j - 1] + expected[j - 2],
                   ctx());
        }
    }
    INFO("accepted pairs " << accepted << " of " << pairs);
    REQUIRE(accepted > pairs / 3);
}

TEST_CASE("B-spline and Catmull-Rom chains play through SetpointStream without gap or repeat",
          "[properties]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 1);
    const std::uint64_t chains = spans_for(1000, 12);
    constexpr int kSpans = 12;

    SECTION("collinear, evenly spaced points give an exact arithmetic progression") {
        // P_i = c + i * n * v on both axes: the curve is the line c + n v + k v per tick, so
        // any gap or repeated tick at a joint breaks the progression.
        for (std::uint64_t chain = 0; chain < chains; ++chain) {
            for (Basis b : {Basis::kUniformBSpline, Basis::kCatmullRom}) {
                const auto n = static_cast<std::uint32_t>(gen.uniform(1, 300));
                std::int64_t c[2], v[2];
                for (int a = 0; a < 2; ++a) {
                    v[a] = gen.uniform(-2000, 2000);
                    c[a] = gen.uniform(-100000000, 100000000);
                }
                std::int32_t pts[2][kSpans + 3];
                for (int a = 0; a < 2; ++a) {
                    for (int i = 0; i < kSpans + 3; ++i) {
                        pts[a][i] = static_cast<std::int32_t>(c[a] + i * std::int64_t{n} * v[a]);
                    }
                }
                const Lsb start[2] = {static_cast<Lsb>(c[0] + n * v[0]),
                                      static_cast<Lsb>(c[1] + n * v[1])};
                SetpointStream<2, 16> stream(start);
                for (int s = 0; s < kSpans; ++s) {
                    Span<2> span;
                    span.basis = b;
                    span.ticks = n;
                    span.tag = static_cast<std::uint32_t>(s + 1);
                    for (int a = 0; a < 2; ++a) {
                        for (int j = 0; j < 4; ++j) span.control[a][j] = pts[a][s + j];
                    }
                    const Status st = stream.push(span);
                    REQUIRE(name(st) == name(Status::kOk));
                }
                const std::uint64_t total = std::uint64_t{n} * kSpans;
                Lsb out[2];
                for (std::uint64_t t = 0; t < total; ++t) {
                    const TickState state = stream.tick(out);
                    EXPECT(state == TickState::kMoving, t);
                    for (int a = 0; a < 2; ++a) {
                        const std::int64_t want =
                            c[a] + std::int64_t{n} * v[a] + static_cast<std::int64_t>(t) * v[a];
                        EXPECT(out[a] == want,
                               std::string(basis_name(b)) + " n=" + std::to_string(n) + " tick " +
                                   std::to_string(t) + " axis " + std::to_string(a) + " got " +
                                   std::to_string(out[a]) + " want " + std::to_string(want));
                    }
                }
                REQUIRE(stream.ticks_executed() == total);
                REQUIRE(stream.spans_completed() == static_cast<std::uint32_t>(kSpans));
                // Dry: it holds the last span's end point, P_{kSpans+1}.
                REQUIRE(stream.tick(out) == TickState::kIdle);
                for (int a = 0; a < 2; ++a) REQUIRE(out[a] == pts[a][kSpans + 1]);
            }
        }
    }

    SECTION("random points: every tick is the reference, joints exact on both sides") {
        for (std::uint64_t chain = 0; chain < chains; ++chain) {
            for (Basis b : {Basis::kUniformBSpline, Basis::kCatmullRom}) {
                // Mostly short spans, sometimes just past the narrow limit (wide state).
                const auto n = static_cast<std::uint32_t>(
                    gen.uniform(0, 7) == 0 ? gen.uniform(880, 1300) : gen.uniform(1, 200));
                std::int32_t pts[2][kSpans + 3];
                for (int a = 0; a < 2; ++a) random_points(gen, pts[a], kSpans + 3);
                // Keep only the prefix of spans the core accepts on both axes.
                std::vector<std::array<std::int32_t, 4>> control[2];
                int spans = 0;
                for (int s = 0; s < kSpans; ++s) {
                    bool ok = true;
                    for (int a = 0; a < 2; ++a) {
                        const std::int32_t p[4] = {pts[a][s], pts[a][s + 1], pts[a][s + 2],
                                                   pts[a][s + 3]};
                        Axis tmp;
                        ok = ok && build(b, p, n, tmp) == Status::kOk;
                    }
                    if (!ok) break;
                    ++spans;
                }
                if (spans == 0) continue;
                Lsb start[2];
                for (int a = 0; a < 2; ++a) {
                    const std::int32_t p[4] = {pts[a][0], pts[a][1], pts[a][2], pts[a][3]};
                    start[a] = static_cast<Lsb>(reference_setpoint(b, p, n, 0));
                }
                SetpointStream<2, 4> stream(start);
                int pushed = 0, done = 0;
                std::uint32_t k = 0;  // tick within span `done`
                Lsb out[2];
                Lsb previous[2] = {start[0], start[1]};
                while (done < spans) {
                    while (pushed < spans && stream.free_slots() > 0) {
                        Span<2> span;
                        span.basis = b;
                        span.ticks = n;
                        span.tag = static_cast<std::uint32_t>(pushed + 100);
                        for (int a = 0; a < 2; ++a) {
                            for (int j = 0; j < 4; ++j) span.control[a][j] = pts[a][pushed + j];
                        }
                        const Status st = stream.push(span);
                        REQUIRE(name(st) == name(Status::kOk));
                        ++pushed;
                    }
                    const TickState state = stream.tick(out);
                    EXPECT(state == TickState::kMoving, k);
                    for (int a = 0; a < 2; ++a) {
                        const std::int32_t p[4] = {pts[a][done], pts[a][done + 1], pts[a][done + 2],
                                                   pts[a][done + 3]};
                        const auto want = reference_setpoint(b, p, n, k);
                        EXPECT(out[a] == want, describe(b, p, n) + " span " + std::to_string(done) +
                                                   " tick " + std::to_string(k) + " got " +
                                                   std::to_string(out[a]));
                        if (k == 0 && done > 0) {
                            // Joint: the previous span's exact end is this span's exact start,
                            // and the setpoint played here is the previous span's tick n.
                            const std::int32_t q[4] = {pts[a][done - 1], pts[a][done],
                                                       pts[a][done + 1], pts[a][done + 2]};
                            EXPECT(same_value(reference_value(b, q, n, n),
                                              reference_value(b, p, n, 0)),
                                   describe(b, q, n));
                            EXPECT(out[a] == reference_setpoint(b, q, n, n), describe(b, q, n));
                            // The step into the joint is the rounded curve's own step.
                            EXPECT(out[a] - previous[a] == reference_setpoint(b, p, n, 0) -
                                                               reference_setpoint(b, q, n, n - 1),
                                   describe(b, q, n));
                        }
                        previous[a] = out[a];
                    }
                    if (++k == n) {
                        k = 0;
                        ++done;
                        REQUIRE(stream.spans_completed() == static_cast<std::uint32_t>(done));
                        REQUIRE(stream.last_completed_tag() ==
                                static_cast<std::uint32_t>(done - 1 + 100));
                    }
                }
                REQUIRE(stream.ticks_executed() ==
                        std::uint64_t{n} * static_cast<std::uint64_t>(spans));
            }
        }
    }
}

// ---- Catmull-Rom -------------------------------------------------------------------------

TEST_CASE("Catmull-Rom spans pass through P1 and P2 and join C1", "[properties]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 2);
    const std::uint64_t pairs = spans_for(1);
    const Basis b = Basis::kCatmullRom;
    std::uint64_t accepted = 0;
    for (std::uint64_t i = 0; i < pairs; ++i) {
        std::int32_t pts[5];
        random_points(gen, pts, 5);
        const std::uint32_t n = gen.ticks();
        const std::int32_t p1[4] = {pts[0], pts[1], pts[2], pts[3]};
        const std::int32_t p2[4] = {pts[1], pts[2], pts[3], pts[4]};
        Axis s1, s2;
        if (build(b, p1, n, s1) != Status::kOk || build(b, p2, n, s2) != Status::kOk) continue;
        ++accepted;
        const auto ctx = [&] { return describe(b, pts, n); };
        // Interpolation, in the core (evaluate_at and the differencer) and the reference.
        EXPECT(core_at(s1, 0) == pts[1], ctx());
        EXPECT(core_at(s1, n) == pts[2], ctx());
        EXPECT(core_at(s2, 0) == pts[2], ctx());
        EXPECT(core_at(s2, n) == pts[3], ctx());
        std::int64_t first = 0, last = 0;
        emit(s1, 0, 1, &first);
        emit(s1, n, 1, &last);
        EXPECT(first == pts[1] && last == pts[2], ctx());
        EXPECT(same_value(reference_value(b, p1, n, 0), Rational{pts[1], 1}), ctx());
        EXPECT(same_value(reference_value(b, p1, n, n), Rational{pts[2], 1}), ctx());
        // C1: p'(1) of span 1 == p'(0) of span 2 == (P3 - P1)/2, exactly.
        const Derivatives e1 = reference_derivatives(b, p1, n, n);
        const Derivatives b2 = reference_derivatives(b, p2, n, 0);
        EXPECT(same_value(e1.d1, b2.d1), ctx() + " " + str(e1.d1) + " vs " + str(b2.d1));
        EXPECT(same_value(e1.d1, Rational{i128{pts[3]} - pts[1], 2}), ctx());
        EXPECT(same_value(core_d1(s1, b, true), core_d1(s2, b, false)), ctx());
        EXPECT(same_value(core_d1(s1, b, true), e1.d1), ctx());
        EXPECT(same_value(core_d1(s1, b, false), reference_derivatives(b, p1, n, 0).d1), ctx());
    }
    INFO("accepted pairs " << accepted << " of " << pairs);
    REQUIRE(accepted > pairs / 3);
}

// ---- Bezier and Hermite end conditions --------------------------------------------------

/// End points and end tangents (in u) of a basis that interpolates its ends: the span must
/// start at p[0], end at p[end_index], and have the tangents `tangents(p)` gives at u = 0, 1.
template <typename Tangents>
void check_end_conditions(Basis b, std::uint64_t seed_offset, int end_index, Tangents tangents,
                          std::uint64_t min_accepted_divisor) {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + seed_offset);
    const std::uint64_t count = spans_for(1);
    std::uint64_t accepted = 0;
    for (std::uint64_t i = 0; i < count; ++i) {
        std::int32_t p[4];
        gen.control(b, p);
        const std::uint32_t n = gen.ticks();
        Axis s;
        if (build(b, p, n, s) != Status::kOk) continue;
        ++accepted;
        const auto ctx = [&] { return describe(b, p, n); };
        EXPECT(core_at(s, 0) == p[0], ctx());
        EXPECT(core_at(s, n) == p[end_index], ctx());
        std::int64_t last = 0;
        emit(s, n, 1, &last);
        EXPECT(last == p[end_index], ctx());
        const auto [t0, t1] = tangents(p);
        EXPECT(same_value(reference_derivatives(b, p, n, 0).d1, t0), ctx());
        EXPECT(same_value(reference_derivatives(b, p, n, n).d1, t1), ctx());
        EXPECT(same_value(core_d1(s, b, false), t0), ctx());
        EXPECT(same_value(core_d1(s, b, true), t1), ctx());
    }
    INFO("accepted " << accepted << " of " << count);
    REQUIRE(accepted > count / min_accepted_divisor);
}

TEST_CASE("Bezier ends at P0 and P3 with tangents 3(P1-P0) and 3(P3-P2)", "[properties]") {
    check_end_conditions(
        Basis::kBezier, 3, 3,
        [](const std::int32_t(&p)[4]) {
            return std::pair{Rational{3 * (i128{p[1]} - p[0]), 1},
                             Rational{3 * (i128{p[3]} - p[2]), 1}};
        },
        3);
}

TEST_CASE("Hermite ends at P0 and P1 with tangents T0 and T1", "[properties]") {
    check_end_conditions(
        Basis::kHermite, 4, 1,
        [](const std::int32_t(&p)[4]) {
            return std::pair{Rational{p[2], 1}, Rational{p[3], 1}};
        },
        4);
}

// ---- Convex hull ------------------------------------------------------------------------

TEST_CASE("B-spline and Bezier setpoints stay within the per-axis hull of their points",
          "[properties]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 5);
    const std::uint64_t count = spans_for(2);
    for (Basis b : {Basis::kUniformBSpline, Basis::kBezier}) {
        std::uint64_t accepted = 0;
        for (std::uint64_t i = 0; i < count; ++i) {
            std::int32_t p[4];
            gen.control(b, p);
            const std::uint32_t n = gen.ticks();
            Axis s;
            if (build(b, p, n, s) != Status::kOk) continue;
            ++accepted;
            const std::int64_t lo = *std::min_element(p, p + 4), hi = *std::max_element(p, p + 4);
            std::vector<std::uint32_t> ticks = extreme_ticks(b, p, n);
            ticks.push_back(n / 2);
            ticks.push_back(static_cast<std::uint32_t>(gen.uniform(0, n)));
            for (std::uint32_t k : ticks) {
                const std::int64_t v = core_at(s, k);
                EXPECT(v >= lo && v <= hi, describe(b, p, n) + " tick " + std::to_string(k) +
                                               " -> " + std::to_string(v));
            }
            // The forward differencer, two ticks from an extreme point.
            const std::uint32_t k0 = ticks.size() > 2 ? ticks[2] : 0;
            if (k0 + 2 <= n) {
                std::int64_t seq[3];
                emit(s, k0, 3, seq);
                for (std::int64_t v : seq) {
                    EXPECT(v >= lo && v <= hi, describe(b, p, n) + " from tick " +
                                                   std::to_string(k0) + " -> " + std::to_string(v));
                }
            }
        }
        INFO(basis_name(b) << " accepted " << accepted << " of " << count);
        REQUIRE(accepted > count / 3);
    }
}

TEST_CASE("Short B-spline and Bezier spans stay in the hull at every tick", "[properties]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 6);
    const std::uint64_t count = spans_for(100, 20);
    for (Basis b : {Basis::kUniformBSpline, Basis::kBezier}) {
        std::uint64_t played = 0;
        for (std::uint64_t i = 0; i < count; ++i) {
            Span<3> span;
            span.basis = b;
            span.ticks = static_cast<std::uint32_t>(gen.uniform(1, 400));
            for (auto& axis : span.control) gen.control(b, axis);
            // A fresh stream starting where the span starts (push() accepts only a span that
            // starts at the stream's position); spans the core rejects are skipped.
            Lsb start[3];
            if (core_start(span, start) != Status::kOk) continue;
            SetpointStream<3, 2> stream(start);
            const Status pushed = stream.push(span);
            REQUIRE(name(pushed) == name(Status::kOk));
            ++played;
            Lsb out[3];
            for (std::uint32_t k = 0; k <= span.ticks; ++k) {
                const TickState st = stream.tick(out);  // k == ticks: idle, holding the end
                EXPECT(st == (k < span.ticks ? TickState::kMoving : TickState::kIdle), k);
                for (int a = 0; a < 3; ++a) {
                    const auto& p = span.control[a];
                    EXPECT(out[a] >= *std::min_element(p, p + 4) &&
                               out[a] <= *std::max_element(p, p + 4),
                           describe(b, p, span.ticks) + " tick " + std::to_string(k));
                }
            }
        }
        INFO(basis_name(b) << " played " << played << " of " << count);
        REQUIRE(played > count / 4);
    }
}

// ---- Translation invariance -------------------------------------------------------------

TEST_CASE("Adding an integer offset to every position shifts every setpoint by it exactly",
          "[properties]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 7);
    const std::uint64_t count = spans_for(2);
    const std::int64_t limit = pathstream::kMaxPositionLsb;
    for (Basis b : kAllBases) {
        const int positions = b == Basis::kHermite ? 2 : 4;  // Hermite tangents do not move
        std::uint64_t accepted = 0;
        for (std::uint64_t i = 0; i < count; ++i) {
            std::int32_t p[4];
            gen.control(b, p);
            const std::uint32_t n = gen.ticks();
            const std::int64_t lo = *std::min_element(p, p + positions);
            const std::int64_t hi = *std::max_element(p, p + positions);
            if (hi - lo > 2 * limit - 2) continue;  // no room to move
            // Offsets of both signs, small ones and ones that push a point to the limit.
            std::int64_t offset = 0;
            switch (gen.uniform(0, 3)) {
                case 0:
                    offset = gen.uniform(-3, 3);
                    break;
                case 1:
                    offset = limit - hi;
                    break;
                case 2:
                    offset = -limit - lo;
                    break;
                default:
                    offset = gen.uniform(-limit - lo, limit - hi);
                    break;
            }
            offset = std::clamp(offset, -limit - lo, limit - hi);  // keep positions in range
            if (offset == 0) offset = hi < limit ? 1 : -1;
            std::int32_t q[4] = {p[0], p[1], p[2], p[3]};
            for (int j = 0; j < positions; ++j) q[j] = static_cast<std::int32_t>(p[j] + offset);
            Axis s, t;
            const Status sp = build(b, p, n, s), sq = build(b, q, n, t);
            // Differences do not depend on the offset, and the curve stays far inside its bound:
            // both are accepted or both rejected for the same reason.
            EXPECT(sp == sq, describe(b, p, n) + " offset " + std::to_string(offset) + ": " +
                                 name(sp) + " vs " + name(sq));
            if (sp != Status::kOk) continue;
            ++accepted;
            const auto ctx = [&] {
                return describe(b, p, n) + " offset " + std::to_string(offset);
            };
            std::vector<std::uint32_t> ticks = {0, n, n / 3,
                                                static_cast<std::uint32_t>(gen.uniform(0, n))};
            for (std::uint32_t k : ticks) {
                EXPECT(core_at(t, k) == core_at(s, k) + offset,
                       ctx() + " tick " + std::to_string(k));
            }
            // The per-tick path too: a few stepped ticks from a random start.
            const auto k0 = static_cast<std::uint32_t>(gen.uniform(0, n));
            const std::uint32_t steps = std::min<std::uint32_t>(4, n - k0 + 1);
            std::int64_t a[4], c[4];
            emit(s, k0, steps, a);
            emit(t, k0, steps, c);
            for (std::uint32_t j = 0; j < steps; ++j) {
                EXPECT(c[j] == a[j] + offset, ctx() + " stepped tick " + std::to_string(k0 + j));
            }
        }
        INFO(basis_name(b) << " accepted " << accepted << " of " << count);
        REQUIRE(accepted > count / 5);
    }
}

// ---- Narrow / wide boundary -------------------------------------------------------------

TEST_CASE("Spans just below and above the 2^32 denominator limit are exact at every tick",
          "[properties]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    SpanGenerator gen(seed + 8);
    struct Boundary {
        Basis basis;
        std::uint32_t narrow_max;
    };
    const Boundary boundaries[] = {{Basis::kUniformBSpline, 894},
                                   {Basis::kCatmullRom, 1290},
                                   {Basis::kBezier, 1625},
                                   {Basis::kHermite, 1625}};
    const std::uint64_t rounds = spans_for(10000, 4);
    for (const Boundary& bd : boundaries) {
        for (std::uint32_t n :
             {bd.narrow_max - 1, bd.narrow_max, bd.narrow_max + 1, bd.narrow_max + 2}) {
            SpanTiming timing;
            const Status ts = pathstream::make_span_timing(bd.basis, n, timing);
            REQUIRE(name(ts) == name(Status::kOk));
            INFO(basis_name(bd.basis) << " n=" << n << " D=" << timing.denominator);
            REQUIRE(pathstream::is_narrow(timing) == (n <= bd.narrow_max));
            REQUIRE(timing.denominator ==
                    std::uint64_t{pathstream::basis_matrix(bd.basis).scale} * n * n * n);
            for (std::uint64_t r = 0; r < rounds; ++r) {
                // Three axes: random styles, plus fixed shapes that keep remainders near D
                // (alternating extremes) and that ride the rounding halves (odd small points).
                Span<3> span;
                span.basis = bd.basis;
                span.ticks = n;
                span.tag = static_cast<std::uint32_t>(r);
                gen.control(bd.basis, span.control[0]);
                gen.control(bd.basis, span.control[1]);
                const auto m =
                    static_cast<std::int32_t>(pathstream::kMaxPositionLsb - gen.uniform(0, 5));
                const std::int32_t extreme[4] = {-m, m, -m, m};
                const std::int32_t odd[4] = {1, -3, 5, 7};
                const std::int32_t* third = r % 2 ? extreme : odd;
                for (int j = 0; j < 4; ++j) span.control[2][j] = third[j];
                Lsb start[3];
                if (core_start(span, start) != Status::kOk) {
                    // Only the random axes may be too steep; retry with a gentle one.
                    for (int a = 0; a < 2; ++a) {
                        for (int j = 0; j < 4; ++j) span.control[a][j] = 1000 * j - 777 * a;
                    }
                    const Status st2 = core_start(span, start);
                    REQUIRE(name(st2) == name(Status::kOk));
                }
                // A fresh stream starting where the span starts.
                SetpointStream<3, 2> stream(start);
                const Status st = stream.push(span);
                REQUIRE(name(st) == name(Status::kOk));
                Lsb out[3];
                for (std::uint32_t k = 0; k < n; ++k) {
                    EXPECT(stream.tick(out) == TickState::kMoving, k);
                    for (int a = 0; a < 3; ++a) {
                        EXPECT(out[a] == reference_setpoint(bd.basis, span.control[a], n, k),
                               describe(bd.basis, span.control[a], n) + " tick " +
                                   std::to_string(k) + " got " + std::to_string(out[a]));
                    }
                }
                REQUIRE(stream.tick(out) == TickState::kIdle);
                for (int a = 0; a < 3; ++a) {
                    REQUIRE(out[a] == reference_setpoint(bd.basis, span.control[a], n, n));
                }
            }
        }
    }
}
