// What the axes do with their setpoints: the plant models of the simulated plotter.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>

namespace pathstream::sim {

/// Per-axis plant model.
enum class PlantModel {
    kIdeal,  ///< position = setpoint, at every tick
    kServo,  ///< linear second-order position loop (ServoParameters)
};

/// Name for reports: "ideal", "servo".
const char* plant_name(PlantModel model);

/// A position-controlled axis as a second-order system from setpoint u to position x, with
/// the velocity and acceleration feed-forward a servo drive adds to its inner loops:
///   x'' = omega^2 (u - x) + 2 zeta omega (v_ff - x') + a_ff,   omega = 2 pi bandwidth_hz.
/// `bandwidth_hz` is the natural frequency f_n (for zeta = 1 the -3 dB bandwidth is
/// 0.644 f_n). zeta = 1 (default) is critically damped: the fastest response without
/// overshoot. Following a ramp of speed v without feed-forward the steady-state lag is
/// 2 zeta v / omega; with v_ff = u' and a_ff = u'' the error obeys the homogeneous equation
/// and decays to zero.
struct ServoParameters {
    double bandwidth_hz = 50;
    double damping = 1.0;  ///< zeta > 0
};

/// Feed-forward held over one tick: what the drive adds to its velocity loop (mm/s) and to
/// its torque, expressed as the acceleration it produces (mm/s^2). Zero: none.
struct FeedForward {
    double velocity = 0;
    double acceleration = 0;
};

/// One servo axis, integrated exactly: the setpoint and the feed-forward are held constant
/// over each tick (zero-order hold, as a drive receiving one setpoint per tick sees it), or
/// the setpoint ramps linearly over the tick (step_interpolated: a drive interpolating between
/// cycle targets), and the linear ODE is solved in closed form over the tick,
/// [x v]_{k+1} = Phi [x v]_k + Gamma [u s v_ff a_ff]_k, with Phi and Gamma taken from the
/// matrix exponential of the augmented system (no integration error, stable for any
/// bandwidth and tick). Units: mm and s (or any length unit, consistently). Host only.
class ServoAxis {
public:
    /// At rest at `start_mm`. Throws std::invalid_argument unless bandwidth_hz, damping and
    /// tick_seconds are finite and > 0.
    ServoAxis(const ServoParameters& parameters, double tick_seconds, double start_mm);

    double position() const { return x_; }  ///< mm
    double velocity() const { return v_; }  ///< mm/s
    /// Advances one tick with `setpoint_mm` and `feed_forward` held over it.
    void step(double setpoint_mm, const FeedForward& feed_forward = {}) {
        advance(setpoint_mm, 0, feed_forward);
    }
    /// Advances one tick with the setpoint moving linearly from `from_mm` (at the tick's
    /// start) to `to_mm` (at its end) and `feed_forward` held over it.
    void step_interpolated(double from_mm, double to_mm, const FeedForward& feed_forward = {}) {
        advance(from_mm, (to_mm - from_mm) / tick_, feed_forward);
    }

private:
    static constexpr std::size_t kInputs = 4;  // u, its slope s, v_ff, a_ff
    void advance(double u, double slope, const FeedForward& ff) {
        const double in[kInputs] = {u, slope, ff.velocity, ff.acceleration};
        double x = phi_[0][0] * x_ + phi_[0][1] * v_;
        double v = phi_[1][0] * x_ + phi_[1][1] * v_;
        for (std::size_t i = 0; i < kInputs; ++i) {
            x += gamma_[0][i] * in[i];
            v += gamma_[1][i] * in[i];
        }
        x_ = x;
        v_ = v;
    }

    std::array<std::array<double, 2>, 2> phi_{};
    std::array<std::array<double, kInputs>, 2> gamma_{};
    double tick_ = 0;
    double x_ = 0;
    double v_ = 0;
};

}  // namespace pathstream::sim
