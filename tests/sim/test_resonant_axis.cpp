// The resonant axis against closed forms: ring-down frequency and decay, the step's steady
// state, a stiff mode vanishing into the servo, the exact discretization against RK4, and the
// parameter checks; the matrix exponential against known exponentials.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "pathstream/sim/matrix_exponential.hpp"
#include "pathstream/sim/plant.hpp"
#include "pathstream/sim/resonant_axis.hpp"

using namespace pathstream::sim;

namespace {

constexpr double kPi = std::numbers::pi;

/// Zero crossings (upward) and same-sign peaks of the tool's ring-down about `rest`, found
/// between ticks from the exact state (position, velocity) with the mode's acceleration.
struct RingDown {
    std::vector<double> crossings;  ///< s, upward through rest
    std::vector<double> peaks;      ///< mm above rest, maxima
};

RingDown ring_down(ResonantAxis& axis, const ResonantMode& m, double tick_s, double rest,
                   double from_s, double to_s) {
    const double w = 2 * kPi * m.frequency_hz;
    RingDown r;
    double t = 0;
    double y_prev = axis.tool_position() - rest, v_prev = axis.tool_velocity();
    while (t < to_s) {
        axis.step(rest);
        t += tick_s;
        const double y = axis.tool_position() - rest, v = axis.tool_velocity();
        if (t > from_s) {
            // The motor has settled: y'' = -w^2 y - 2 zeta w y'.
            if (y_prev < 0 && y >= 0) r.crossings.push_back(t - y / v);  // Newton from tick
            if (v_prev > 0 && v <= 0) {
                const double a = -w * w * y - 2 * m.damping * w * v;
                const double tau = -v / a;  // back to the velocity zero
                r.peaks.push_back(y + v * tau + a * tau * tau / 2);
            }
        }
        y_prev = y, v_prev = v;
    }
    return r;
}

}  // namespace

TEST_CASE("matrix exponential of a diagonal and a rotation generator", "[sim][plant]") {
    SquareMatrix d(2);
    d(0, 0) = -3;
    d(1, 1) = 1.5;
    const SquareMatrix e = matrix_exponential(d);
    CHECK(e(0, 0) == Approx(std::exp(-3.0)).epsilon(1e-14));
    CHECK(e(1, 1) == Approx(std::exp(1.5)).epsilon(1e-14));
    CHECK(e(0, 1) == 0);
    SquareMatrix r(2);
    r(0, 1) = -40;
    r(1, 0) = 40;
    const SquareMatrix q = matrix_exponential(r);
    CHECK(q(0, 0) == Approx(std::cos(40.0)).margin(1e-12));
    CHECK(q(1, 0) == Approx(std::sin(40.0)).margin(1e-12));
    SquareMatrix bad(1);
    bad(0, 0) = std::nan("");
    CHECK_THROWS_AS(matrix_exponential(bad), std::invalid_argument);
}

TEST_CASE("a mode rings down at its damped frequency and decay", "[sim][plant]") {
    const double tick_s = 1e-5;  // 100 kHz: interpolation errors far below 1e-6
    for (const ResonantMode m : {ResonantMode{40, 0.05}, ResonantMode{73, 0.002}}) {
        ResonantAxis axis({50, 1.0}, {m}, tick_s, 0);
        // A step: the servo settles within 0.1 s (e^-31), the mode keeps ringing.
        const RingDown r = ring_down(axis, m, tick_s, 1.0, 0.1, 0.1 + 12 / m.frequency_hz);
        REQUIRE(r.crossings.size() >= 10);
        REQUIRE(r.peaks.size() >= 10);
        const double periods = static_cast<double>(r.crossings.size() - 1);
        const double f_d = periods / (r.crossings.back() - r.crossings.front());
        const double expected_f_d = m.frequency_hz * std::sqrt(1 - m.damping * m.damping);
        CHECK(f_d == Approx(expected_f_d).epsilon(1e-6));
        const double n = static_cast<double>(r.peaks.size() - 1);
        const double decrement = std::log(r.peaks.front() / r.peaks.back()) / n;
        const double zeta = decrement / std::sqrt(4 * kPi * kPi + decrement * decrement);
        CHECK(zeta == Approx(m.damping).epsilon(1e-6));
    }
}

TEST_CASE("a step response ends exactly at the setpoint, every mass at rest", "[sim][plant]") {
    ResonantAxis axis({50, 1.0}, {{40, 0.05}, {120, 0.1}}, 1e-3, 2.5);
    CHECK(axis.modes() == 2);
    CHECK(axis.tool_position() == 2.5);
    for (int k = 0; k < 5000; ++k) axis.step(7.5);  // 5 s: e^-(0.05 * 251 * 5) = 2e-28
    CHECK(axis.motor_position() == Approx(7.5).margin(1e-12));
    CHECK(axis.mass_position(1) == Approx(7.5).margin(1e-12));
    CHECK(axis.tool_position() == Approx(7.5).margin(1e-12));
    CHECK(axis.tool_velocity() == Approx(0).margin(1e-6));
}

TEST_CASE("a stiff mode tends to the servo alone", "[sim][plant]") {
    const double tick_s = 1e-4;
    const auto difference = [&](double frequency_hz) {
        ServoAxis servo({50, 1.0}, tick_s, 0);
        ResonantAxis axis({50, 1.0}, {{frequency_hz, 0.5}}, tick_s, 0);
        ResonantAxis bare({50, 1.0}, {}, tick_s, 0);
        double worst = 0;
        for (int k = 0; k < 2000; ++k) {  // a ramp of 100 mm/s for 0.2 s
            const double u = 100 * k * tick_s;
            servo.step(u), axis.step(u), bare.step(u);
            CHECK(bare.tool_position() == Approx(servo.position()).margin(1e-12));
            worst = std::max(worst, std::fabs(axis.tool_position() - servo.position()));
        }
        return worst;
    };
    const double at_500 = difference(500), at_4000 = difference(4000);
    // Base excitation through spring and damper: no lag behind a ramp, only the response to
    // the motor's acceleration, about a / w_i^2: a 64th at 8 times the frequency.
    CHECK(at_500 < 2e-3);
    CHECK(at_4000 < at_500 / 30);
}

TEST_CASE("the exact discretization equals a fine RK4 integration", "[sim][plant]") {
    const ServoParameters servo{30, 0.7};
    const std::vector<ResonantMode> modes{{40, 0.05}, {95, 0.2}};
    const double tick_s = 1e-3;
    ResonantAxis axis(servo, modes, tick_s, 0);
    const SquareMatrix a = resonant_axis_system(servo, modes);
    const std::size_t n = a.size();
    std::vector<double> s(n, 0.0);
    const auto derivative = [&](const std::vector<double>& x) {
        std::vector<double> d(n, 0.0);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = 0; j < n; ++j) d[i] += a(i, j) * x[j];
        return d;
    };
    const int substeps = 100;
    const double h = tick_s / substeps;
    for (int k = 0; k < 300; ++k) {
        const double u = k < 150 ? 0.02 * k : 3.0;  // a ramp, then a hold
        s[n - 1] = u;
        for (int i = 0; i < substeps; ++i) {
            std::vector<double> x = s;
            const auto k1 = derivative(x);
            for (std::size_t j = 0; j < n; ++j) x[j] = s[j] + h / 2 * k1[j];
            const auto k2 = derivative(x);
            for (std::size_t j = 0; j < n; ++j) x[j] = s[j] + h / 2 * k2[j];
            const auto k3 = derivative(x);
            for (std::size_t j = 0; j < n; ++j) x[j] = s[j] + h * k3[j];
            const auto k4 = derivative(x);
            for (std::size_t j = 0; j < n; ++j)
                s[j] += h / 6 * (k1[j] + 2 * k2[j] + 2 * k3[j] + k4[j]);
        }
        axis.step(u);
        CHECK(axis.motor_position() == Approx(s[0]).margin(1e-9));
        CHECK(axis.motor_velocity() == Approx(s[1]).margin(1e-7));
        CHECK(axis.tool_position() == Approx(s[4]).margin(1e-9));
        CHECK(axis.tool_velocity() == Approx(s[5]).margin(1e-7));
    }
}

TEST_CASE("resonant modes are checked", "[sim][plant]") {
    const auto message = [](const ResonantMode& m) {
        try {
            ResonantAxis({50, 1.0}, {{40, 0.05}, m}, 1e-3, 0);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(message({0, 0.05}) ==
          "resonant mode 2: mode frequency 0 Hz is impossible (allowed: > 0 and below half "
          "the tick rate, 500 Hz)");
    CHECK(message({500, 0.05}).find("below half the tick rate, 500 Hz") != std::string::npos);
    CHECK(message({std::nan(""), 0.05}).find("mode frequency nan Hz") != std::string::npos);
    CHECK(message({-3, 0.05}).find("mode frequency -3 Hz") != std::string::npos);
    CHECK(message({40, 0}) ==
          "resonant mode 2: mode damping ratio 0 is impossible (allowed: > 0 and <= 1)");
    CHECK(message({40, 1.5}).find("damping ratio 1.5") != std::string::npos);
    CHECK(message({40, 1}) == "no error");
    CHECK_THROWS_AS(ResonantAxis({0, 1.0}, {}, 1e-3, 0), std::invalid_argument);
    CHECK_THROWS_AS(ResonantAxis({50, 1.0}, {}, 0, 0), std::invalid_argument);
}
