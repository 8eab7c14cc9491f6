#include "pathstream/sim/resonant_axis.hpp"

#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace pathstream::sim {
namespace {

bool positive(double v) {
    return std::isfinite(v) && v > 0;
}

double omega_of(double hz) {
    return 2 * std::numbers::pi * hz;
}

}  // namespace

void check_resonant_mode(const ResonantMode& mode, double tick_hz) {
    std::ostringstream m;
    if (!positive(mode.frequency_hz) || mode.frequency_hz >= tick_hz / 2) {
        m << "mode frequency " << mode.frequency_hz
          << " Hz is impossible (allowed: > 0 and below half the tick rate, " << tick_hz / 2
          << " Hz)";
        throw std::invalid_argument(m.str());
    }
    if (!positive(mode.damping) || mode.damping > 1) {
        m << "mode damping ratio " << mode.damping << " is impossible (allowed: > 0 and <= 1)";
        throw std::invalid_argument(m.str());
    }
}

SquareMatrix resonant_axis_system(const ServoParameters& servo,
                                  const std::vector<ResonantMode>& modes) {
    const std::size_t n = 2 * (modes.size() + 1);
    SquareMatrix a(n + 1);  // the last row and column: u, constant
    const double w = omega_of(servo.bandwidth_hz);
    a(0, 1) = 1;
    a(1, 0) = -w * w;
    a(1, 1) = -2 * servo.damping * w;
    a(1, n) = w * w;
    for (std::size_t i = 1; i <= modes.size(); ++i) {
        const double wi = omega_of(modes[i - 1].frequency_hz);
        const double k = wi * wi;                        // stiffness over mass
        const double c = 2 * modes[i - 1].damping * wi;  // damping over mass
        const std::size_t y = 2 * i, v = y + 1, base = y - 2, base_v = y - 1;
        a(y, v) = 1;
        a(v, base) = k;
        a(v, y) = -k;
        a(v, base_v) = c;
        a(v, v) = -c;
    }
    return a;
}

ResonantAxis::ResonantAxis(const ServoParameters& servo, const std::vector<ResonantMode>& modes,
                           double tick_seconds, double start_mm)
    : modes_(modes.size()), n_(2 * (modes.size() + 1)) {
    // ServoAxis's own checks, and its messages.
    const ServoAxis servo_check(servo, tick_seconds, start_mm);
    (void)servo_check;
    for (std::size_t i = 0; i < modes.size(); ++i) {
        try {
            check_resonant_mode(modes[i], 1 / tick_seconds);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("resonant mode " + std::to_string(i + 1) + ": " + e.what());
        }
    }
    SquareMatrix a = resonant_axis_system(servo, modes);
    for (std::size_t i = 0; i < a.size(); ++i)
        for (std::size_t j = 0; j < a.size(); ++j) a(i, j) *= tick_seconds;
    const SquareMatrix e = matrix_exponential(a);  // [[Phi Gamma] [0 1]]
    phi_.resize(n_ * n_);
    gamma_.resize(n_);
    for (std::size_t i = 0; i < n_; ++i) {
        for (std::size_t j = 0; j < n_; ++j) phi_[i * n_ + j] = e(i, j);
        gamma_[i] = e(i, n_);
    }
    state_.assign(n_, 0.0);
    for (std::size_t i = 0; i < n_; i += 2) state_[i] = start_mm;
    next_.assign(n_, 0.0);
}

void ResonantAxis::step(double setpoint_mm) {
    for (std::size_t i = 0; i < n_; ++i) {
        const double* row = &phi_[i * n_];
        double s = gamma_[i] * setpoint_mm;
        for (std::size_t j = 0; j < n_; ++j) s += row[j] * state_[j];
        next_[i] = s;
    }
    state_.swap(next_);
}

}  // namespace pathstream::sim
