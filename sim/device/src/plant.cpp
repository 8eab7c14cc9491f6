#include "pathstream/sim/plant.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace pathstream::sim {
namespace {

using Matrix3 = std::array<std::array<double, 3>, 3>;

Matrix3 multiply(const Matrix3& a, const Matrix3& b) {
    Matrix3 c{};
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) c[i][j] += a[i][k] * b[k][j];
    return c;
}

/// exp(m) by scaling and squaring with a Taylor series: scale until the norm is below 1/2,
/// sum 20 terms (truncation below 1e-25 relative), square back.
Matrix3 exponential(Matrix3 m) {
    double norm = 0;
    for (const auto& row : m) {
        double s = 0;
        for (double v : row) s += std::fabs(v);
        norm = std::fmax(norm, s);
    }
    int squarings = 0;
    while (norm > 0.5) {
        norm /= 2;
        ++squarings;
    }
    const double scale = std::ldexp(1.0, -squarings);
    for (auto& row : m)
        for (double& v : row) v *= scale;
    Matrix3 sum{}, term{};
    for (int i = 0; i < 3; ++i) sum[i][i] = term[i][i] = 1;
    for (int n = 1; n <= 20; ++n) {
        term = multiply(term, m);
        for (auto& row : term)
            for (double& v : row) v /= n;
        for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j) sum[i][j] += term[i][j];
    }
    for (int i = 0; i < squarings; ++i) sum = multiply(sum, sum);
    return sum;
}

}  // namespace

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
    : x_(start_mm) {
    const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
    if (!positive(p.bandwidth_hz))
        throw std::invalid_argument("servo bandwidth must be a positive number of Hz");
    if (!positive(p.damping)) throw std::invalid_argument("servo damping ratio must be positive");
    if (!positive(tick_seconds)) throw std::invalid_argument("tick period must be positive");
    const double omega = 2 * std::numbers::pi * p.bandwidth_hz;
    // d/dt [x v u] = M [x v u] with u constant over the tick: exp(M T) = [[Phi Gamma] [0 1]].
    Matrix3 m{};
    m[0][1] = tick_seconds;
    m[1][0] = -omega * omega * tick_seconds;
    m[1][1] = -2 * p.damping * omega * tick_seconds;
    m[1][2] = omega * omega * tick_seconds;
    const Matrix3 e = exponential(m);
    for (int i = 0; i < 2; ++i) {
        for (int j = 0; j < 2; ++j) phi_[i][j] = e[i][j];
        gamma_[i] = e[i][2];
    }
}

}  // namespace pathstream::sim
