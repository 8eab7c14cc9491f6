// The servo plant's feed-forward inputs: exact velocity and acceleration feed-forward cut the
// following error of a ramp and of a cubic by orders of magnitude, and the closed-form
// discretisation (held or interpolated setpoint, held feed-forward) matches a fine RK4.
#include <catch2/catch.hpp>
#include <cmath>
#include <functional>
#include <numbers>

#include "pathstream/sim/matrix_exponential.hpp"
#include "pathstream/sim/plant.hpp"

using pathstream::sim::FeedForward;
using pathstream::sim::ServoAxis;
using pathstream::sim::ServoParameters;

namespace {

constexpr double kTick = 0.001;
const ServoParameters kServo{50, 1.0};

struct Command {
    std::function<double(double)> x, v, a;  // position, velocity, acceleration at time t
};

// Largest |command - position| at the tick instants from `first` to `ticks`, the setpoint held over
// each tick at the command's value at the tick's middle (the hold then averages to the command),
// with or without the command's velocity and acceleration there as feed-forward.
double max_error_held(const Command& c, int first, int ticks, bool feed_forward) {
    ServoAxis axis(kServo, kTick, c.x(0));
    double worst = 0;
    for (int k = 0; k < ticks; ++k) {
        const double mid = (k + 0.5) * kTick;
        const FeedForward ff = feed_forward ? FeedForward{c.v(mid), c.a(mid)} : FeedForward{};
        axis.step(c.x(mid), ff);
        if (k >= first) worst = std::fmax(worst, std::fabs(c.x((k + 1) * kTick) - axis.position()));
    }
    return worst;
}

// The same with the setpoint interpolated linearly between the command's tick values and the
// slope of that line as velocity feed-forward.
double max_error_interpolated(const Command& c, int first, int ticks, bool feed_forward) {
    ServoAxis axis(kServo, kTick, c.x(0));
    double worst = 0;
    for (int k = 0; k < ticks; ++k) {
        const double from = c.x(k * kTick), to = c.x((k + 1) * kTick);
        const FeedForward ff =
            feed_forward ? FeedForward{(to - from) / kTick, c.a((k + 0.5) * kTick)} : FeedForward{};
        axis.step_interpolated(from, to, ff);
        if (k >= first) worst = std::fmax(worst, std::fabs(to - axis.position()));
    }
    return worst;
}

// The axis starts at rest: the ramp's velocity jump at t = 0 is a transient (e^(-omega t),
// gone after 200 ticks at 50 Hz), so its error counts from then on; the cubic starts at rest.
const Command kRamp{[](double t) { return 100 * t; }, [](double) { return 100.0; },
                    [](double) { return 0.0; }};
const Command kCubic{[](double t) { return 2000 * t * t * t; },
                     [](double t) { return 6000 * t * t; }, [](double t) { return 12000 * t; }};

// One tick of the continuous system by RK4 with `n` substeps: setpoint u0 + s t.
void rk4(double& x, double& v, double u0, double s, const FeedForward& ff, const ServoParameters& p,
         int n) {
    const double w = 2 * std::numbers::pi * p.bandwidth_hz, z = p.damping, h = kTick / n;
    auto acc = [&](double t, double xx, double vv) {
        return w * w * (u0 + s * t - xx) + 2 * z * w * (ff.velocity - vv) + ff.acceleration;
    };
    for (int i = 0; i < n; ++i) {
        const double t = i * h;
        const double k1x = v, k1v = acc(t, x, v);
        const double k2x = v + h / 2 * k1v, k2v = acc(t + h / 2, x + h / 2 * k1x, v + h / 2 * k1v);
        const double k3x = v + h / 2 * k2v, k3v = acc(t + h / 2, x + h / 2 * k2x, v + h / 2 * k2v);
        const double k4x = v + h * k3v, k4v = acc(t + h, x + h * k3x, v + h * k3v);
        x += h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
        v += h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
    }
}

}  // namespace

TEST_CASE("servo feed-forward: a ramp is followed without lag", "[sim][servo]") {
    // Without feed-forward the lag settles at 2 zeta v / omega = 0.64 mm at 100 mm/s, 50 Hz.
    const double lag = 2 * 100 / (2 * std::numbers::pi * 50);
    const double without = max_error_held(kRamp, 200, 300, false);
    CHECK(without == Approx(lag).epsilon(0.01));
    CHECK(max_error_interpolated(kRamp, 200, 300, false) == Approx(lag).epsilon(0.01));
    // With it the error obeys the homogeneous equation: once the start has died away, only the
    // hold's ripple is left (none when the setpoint ramps with the command).
    CHECK(max_error_held(kRamp, 200, 300, true) < 1e-4 * without);
    CHECK(max_error_interpolated(kRamp, 200, 300, true) < 1e-9);
}

TEST_CASE("servo feed-forward: a cubic is followed within microns", "[sim][servo]") {
    const double without = max_error_held(kCubic, 0, 200, false);
    CHECK(without > 1);  // the velocity reaches 240 mm/s: a lag above a mm
    CHECK(max_error_interpolated(kCubic, 0, 200, false) > 1);
    CHECK(max_error_held(kCubic, 0, 200, true) < 1e-3 * without);
    // Interpolated: the line between tick values misses the cubic by ~a T^2 / 8 inside the
    // tick, which the held acceleration averages out by the tick's end.
    CHECK(max_error_interpolated(kCubic, 0, 200, true) < 1e-3 * without);
}

TEST_CASE("servo discretisation with feed-forward matches a fine RK4", "[sim][servo]") {
    for (const ServoParameters p : {ServoParameters{50, 1.0}, ServoParameters{120, 0.3}}) {
        ServoAxis axis(p, kTick, 1.0);
        double x = 1.0, v = 0;
        for (int k = 0; k < 60; ++k) {
            const double u = std::sin(k * 0.3) * 5, s = std::cos(k * 0.7) * 400;
            const FeedForward ff{std::sin(k * 0.11) * 80, std::cos(k * 0.13) * 3000};
            if (k % 2 == 0) {
                axis.step(u, ff);
                rk4(x, v, u, 0, ff, p, 400);
            } else {
                axis.step_interpolated(u, u + s * kTick, ff);
                rk4(x, v, u, s, ff, p, 400);
            }
            INFO("zeta " << p.damping << " tick " << k);
            REQUIRE(axis.position() == Approx(x).margin(1e-10));
            REQUIRE(axis.velocity() == Approx(v).margin(1e-7));
        }
    }
}

TEST_CASE("servo without feed-forward: a held and an interpolated constant agree", "[sim][servo]") {
    ServoAxis held(kServo, kTick, 0), ramped(kServo, kTick, 0);
    for (int k = 0; k < 50; ++k) {
        held.step(2.0);
        ramped.step_interpolated(2.0, 2.0);
        REQUIRE(held.position() == Approx(ramped.position()).margin(1e-15));
    }
}

TEST_CASE("matrix exponential of a rotation and of a nilpotent matrix", "[sim][servo]") {
    using pathstream::sim::SquareMatrix;
    // exp([[0 -a] [a 0]]) is the rotation by a; a large a exercises the scaling and squaring.
    for (const double a : {0.25, 3.0, 40.0}) {
        SquareMatrix m(2);
        m(0, 1) = -a;
        m(1, 0) = a;
        const SquareMatrix e = pathstream::sim::matrix_exponential(m);
        CHECK(e(0, 0) == Approx(std::cos(a)).margin(1e-12));
        CHECK(e(0, 1) == Approx(-std::sin(a)).margin(1e-12));
        CHECK(e(1, 0) == Approx(std::sin(a)).margin(1e-12));
    }
    // A strictly upper triangular 3x3: the series ends, exp = I + N + N^2 / 2.
    SquareMatrix n(3);
    n(0, 1) = 2;
    n(1, 2) = 3;
    const SquareMatrix e = pathstream::sim::matrix_exponential(n);
    CHECK(e(0, 2) == Approx(3.0));
    CHECK(e(0, 1) == Approx(2.0));
    CHECK(e(2, 2) == Approx(1.0));
}
