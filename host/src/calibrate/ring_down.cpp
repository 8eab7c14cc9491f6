#include "pathstream/host/ring_down.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace pathstream::host {
namespace {

/// Least-squares slope of y over x.
double slope(const std::vector<double>& x, const std::vector<double>& y) {
    const double n = static_cast<double>(x.size());
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (std::size_t i = 0; i < x.size(); ++i) {
        sx += x[i];
        sy += y[i];
        sxx += x[i] * x[i];
        sxy += x[i] * y[i];
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

RingDown fit_ring_down(const RingDownSamples& s, double floor) {
    const std::size_t n = s.value.size();
    if (n < 16 || s.time.size() != n)
        throw std::invalid_argument("ring-down: at least 16 samples are needed");
    for (std::size_t i = 0; i < n; ++i) {
        if (!std::isfinite(s.value[i]) || !std::isfinite(s.time[i]))
            throw std::invalid_argument("ring-down: sample " + std::to_string(i) +
                                        " is not finite");
        if (i > 0 && !(s.time[i] > s.time[i - 1]))
            throw std::invalid_argument("ring-down: times must increase (sample " +
                                        std::to_string(i) + ")");
    }
    double rest = 0;
    const std::size_t tail = n - n / 5;
    for (std::size_t i = tail; i < n; ++i) rest += s.value[i];
    rest /= static_cast<double>(n - tail);
    // Zero crossings about the rest value, and the largest |deviation| between them.
    std::vector<double> crossings, amplitudes;
    double peak = 0;
    bool seen_crossing = false;
    for (std::size_t i = 1; i < n; ++i) {
        const double a = s.value[i - 1] - rest, b = s.value[i] - rest;
        if (seen_crossing) peak = std::max(peak, std::fabs(a));
        if ((a < 0 && b >= 0) || (a > 0 && b <= 0)) {
            const double t = s.time[i - 1] + (s.time[i] - s.time[i - 1]) * a / (a - b);
            if (seen_crossing) amplitudes.push_back(peak);
            crossings.push_back(t);
            seen_crossing = true;
            peak = 0;
        }
    }
    // Half-cycles until the ringing sinks into the noise.
    std::size_t used = 0;
    while (used < amplitudes.size() && amplitudes[used] >= floor * amplitudes.front()) ++used;
    if (used < 4) {
        throw std::invalid_argument("ring-down: " + std::to_string(used) +
                                    " half-cycles above the noise; at least 4 are needed (a "
                                    "longer record, or a stronger excitation)");
    }
    std::vector<double> index(used + 1), times(crossings.begin(), crossings.begin() + used + 1);
    for (std::size_t k = 0; k <= used; ++k) index[k] = static_cast<double>(k);
    const double half_period = slope(index, times);
    std::vector<double> log_amplitude(used), at(used);
    for (std::size_t k = 0; k < used; ++k) {
        log_amplitude[k] = std::log(amplitudes[k]);
        at[k] = static_cast<double>(k) * half_period;
    }
    const double decay = -slope(at, log_amplitude);  // zeta * omega_n, 1/s
    const double omega_d = std::numbers::pi / half_period;
    const double omega_n = std::sqrt(decay * decay + omega_d * omega_d);
    RingDown r;
    r.damped_hz = omega_d / (2 * std::numbers::pi);
    r.frequency_hz = omega_n / (2 * std::numbers::pi);
    r.damping = std::max(0.0, decay / omega_n);
    r.half_cycles = used;
    r.first_amplitude = amplitudes.front();
    return r;
}

}  // namespace pathstream::host
