#include "pathstream/sim/plant.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "pathstream/sim/matrix_exponential.hpp"

namespace pathstream::sim {

const char* plant_name(PlantModel model) {
    switch (model) {
        case PlantModel::kIdeal:
            return "ideal";
        case PlantModel::kServo:
            return "servo";
    }
    return "unknown";
}

ServoAxis::ServoAxis(const ServoParameters& p, double tick_seconds, double start_mm)
    : tick_(tick_seconds), x_(start_mm) {
    const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
    if (!positive(p.bandwidth_hz))
        throw std::invalid_argument("servo bandwidth must be a positive number of Hz");
    if (!positive(p.damping)) throw std::invalid_argument("servo damping ratio must be positive");
    if (!positive(tick_seconds)) throw std::invalid_argument("tick period must be positive");
    const double omega = 2 * std::numbers::pi * p.bandwidth_hz;
    // d/dt [x v u s v_ff a_ff] = M [x v u s v_ff a_ff]: u' = s (the setpoint's slope over the
    // tick, 0 for a hold), the inputs constant. exp(M T) = [[Phi Gamma] [0 exp(N T)]]; its
    // first two rows are all a step needs.
    constexpr std::size_t n = 2 + kInputs;
    SquareMatrix m(n);
    const double t = tick_seconds;
    m(0, 1) = t;
    m(1, 0) = -omega * omega * t;
    m(1, 1) = -2 * p.damping * omega * t;
    m(1, 2) = omega * omega * t;
    m(1, 4) = 2 * p.damping * omega * t;
    m(1, 5) = t;
    m(2, 3) = t;
    const SquareMatrix e = matrix_exponential(m);
    for (std::size_t i = 0; i < 2; ++i) {
        for (std::size_t j = 0; j < 2; ++j) phi_[i][j] = e(i, j);
        for (std::size_t j = 0; j < kInputs; ++j) gamma_[i][j] = e(i, 2 + j);
    }
}

}  // namespace pathstream::sim
