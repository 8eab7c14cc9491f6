// An axis whose mechanics ring: the servo of plant.hpp driving a chain of resonant modes, the
// tool at its end (docs/simulator.md, "Resonant modes").
#pragma once

#include <cstddef>
#include <vector>

#include "pathstream/sim/matrix_exponential.hpp"
#include "pathstream/sim/plant.hpp"

namespace pathstream::sim {

/// One resonant mode: a second mass on a spring and damper, excited through its base.
struct ResonantMode {
    double frequency_hz = 0;  ///< natural frequency f_i (undamped), Hz
    double damping = 0;       ///< damping ratio zeta_i, in (0, 1]
};

/// Throws std::invalid_argument, naming the value, unless `mode.frequency_hz` is finite, > 0
/// and below the Nyquist frequency tick_hz / 2 (a faster mode cannot be seen in positions
/// sampled once per tick) and `mode.damping` is in (0, 1]. `tick_hz` must be > 0.
void check_resonant_mode(const ResonantMode& mode, double tick_hz);

/// One axis as a linear system from setpoint u to tool position, units mm and s:
///   motor (the servo of ServoAxis):  x'' = w^2 (u - x) - 2 zeta w x'
///   mode i = 1..M:  y_i'' = w_i^2 (y_{i-1} - y_i) + 2 zeta_i w_i (y_{i-1}' - y_i')
/// with y_0 = x and w_i = 2 pi f_i: each mode is a spring-damper second mass whose base is the
/// previous one (a cascade: carriage, gantry, tool holder...). The tool is y_M; no mode acts
/// back on the one before it. The state [x x' y_1 y_1' ... y_M y_M'] is advanced exactly over
/// each tick with u held (zero-order hold): s_{k+1} = Phi s_k + Gamma u_k, Phi and Gamma from
/// the matrix exponential of the system augmented with u. A step costs O((2M + 2)^2).
class ResonantAxis {
public:
    /// At rest at `start_mm` (every mass there, every velocity 0). Throws
    /// std::invalid_argument for servo parameters ServoAxis refuses, a tick_seconds that is
    /// not finite and > 0, or a mode check_resonant_mode refuses (its message names the mode's
    /// place in `modes`). No modes: the servo alone, tool = motor.
    ResonantAxis(const ServoParameters& servo, const std::vector<ResonantMode>& modes,
                 double tick_seconds, double start_mm);

    std::size_t modes() const { return modes_; }                     ///< M
    double motor_position() const { return state_[0]; }              ///< x, mm
    double motor_velocity() const { return state_[1]; }              ///< x', mm/s
    double tool_position() const { return state_[2 * modes_]; }      ///< y_M (x without modes)
    double tool_velocity() const { return state_[2 * modes_ + 1]; }  ///< y_M', mm/s
    /// y_i (i = 0: the motor), i <= modes(); not checked.
    double mass_position(std::size_t i) const { return state_[2 * i]; }

    /// Advances one tick with `setpoint_mm` held over it.
    void step(double setpoint_mm);

private:
    std::size_t modes_ = 0;
    std::size_t n_ = 2;          // state size, 2 (M + 1)
    std::vector<double> phi_;    // n x n, row-major
    std::vector<double> gamma_;  // n
    std::vector<double> state_;  // n
    std::vector<double> next_;   // n, scratch
};

/// The continuous-time system matrix of the augmented state [s u] (size 2 M + 3, the last row
/// 0): d/dt [s u] = A [s u]. What ResonantAxis discretizes; tests integrate it independently.
SquareMatrix resonant_axis_system(const ServoParameters& servo,
                                  const std::vector<ResonantMode>& modes);

}  // namespace pathstream::sim
