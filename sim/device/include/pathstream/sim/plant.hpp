// What the axes do with their setpoints: the plant models of the simulated plotter.
#pragma once

#include <array>

namespace pathstream::sim {

/// Per-axis plant model.
enum class PlantModel {
    kIdeal,  ///< position = setpoint, at every tick
    kServo,  ///< linear second-order position loop (ServoParameters)
};

/// Name for reports: "ideal", "servo".
const char* plant_name(PlantModel model);

/// A position-controlled axis as a second-order system from setpoint u to position x:
///   x'' = omega^2 (u - x) - 2 zeta omega x',   omega = 2 pi bandwidth_hz.
/// `bandwidth_hz` is the natural frequency f_n (for zeta = 1 the -3 dB bandwidth is
/// 0.644 f_n). zeta = 1 (default) is critically damped: the fastest response without
/// overshoot. Following a ramp of speed v, the steady-state lag is 2 zeta v / omega.
struct ServoParameters {
    double bandwidth_hz = 50;
    double damping = 1.0;  ///< zeta > 0
};

/// One servo axis, integrated exactly: the setpoint is held constant over each tick (zero-order
/// hold, as a drive receiving one setpoint per tick sees it), and the linear ODE is solved in
/// closed form over the tick, [x v]_{k+1} = Phi [x v]_k + Gamma u_k, with Phi and Gamma taken
/// from the matrix exponential of the augmented system (no integration error, stable for any
/// bandwidth and tick). Units: mm and s. Host only.
class ServoAxis {
public:
    /// At rest at `start_mm`. Throws std::invalid_argument unless bandwidth_hz, damping and
    /// tick_seconds are finite and > 0.
    ServoAxis(const ServoParameters& parameters, double tick_seconds, double start_mm);

    double position() const { return x_; }  ///< mm
    double velocity() const { return v_; }  ///< mm/s
    /// Advances one tick with `setpoint_mm` held over it.
    void step(double setpoint_mm) {
        const double x = phi_[0][0] * x_ + phi_[0][1] * v_ + gamma_[0] * setpoint_mm;
        const double v = phi_[1][0] * x_ + phi_[1][1] * v_ + gamma_[1] * setpoint_mm;
        x_ = x;
        v_ = v;
    }

private:
    std::array<std::array<double, 2>, 2> phi_{};
    std::array<double, 2> gamma_{};
    double x_ = 0;
    double v_ = 0;
};

}  // namespace pathstream::sim
