#include "pathstream/machine/shaper_design.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <map>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "pathstream/machine/machine.hpp"

namespace pathstream::host {
namespace {

struct NamedType {
    ShaperType type;
    const char* name;
};
constexpr NamedType kNames[] = {
    {ShaperType::kZv, "zv"},
    {ShaperType::kZvd, "zvd"},
    {ShaperType::kMzv, "mzv"},
    {ShaperType::kEi, "ei"},
    {ShaperType::kTwoHumpEi, "2hump_ei"},
    {ShaperType::kThreeHumpEi, "3hump_ei"},
};

/// The tolerated vibration of the EI family: 5 % at the design frequency's neighbours.
constexpr double kEiTolerance = 0.05;

std::vector<ShaperImpulse> normalised(std::vector<double> weights, std::vector<double> periods,
                                      double damped_period) {
    double sum = 0;
    for (double w : weights) sum += w;
    std::vector<ShaperImpulse> out;
    for (std::size_t i = 0; i < weights.size(); ++i)
        out.push_back({periods[i] * damped_period, weights[i] / sum});
    return out;
}

}  // namespace

const char* shaper_type_name(ShaperType type) {
    for (const NamedType& n : kNames)
        if (n.type == type) return n.name;
    return "unknown";
}

std::optional<ShaperType> shaper_type_from_name(const std::string& name) {
    for (const NamedType& n : kNames)
        if (name == n.name) return n.type;
    return std::nullopt;
}

std::string shaper_type_names() {
    std::string s;
    for (const NamedType& n : kNames) s += (s.empty() ? "" : ", ") + std::string(n.name);
    return s;
}

std::vector<ShaperImpulse> shaper_impulses(const ShaperSpec& spec) {
    if (!std::isfinite(spec.frequency_hz) || spec.frequency_hz <= 0)
        throw std::invalid_argument("shaper frequency must be a positive number of Hz");
    if (!std::isfinite(spec.damping) || spec.damping < 0 || spec.damping >= 1)
        throw std::invalid_argument("shaper damping ratio must be at least 0 and below 1");
    const double zeta = spec.damping;
    const double root = std::sqrt(1 - zeta * zeta);
    const double period = 1 / (spec.frequency_hz * root);  // damped period
    const double k = std::exp(-zeta * std::numbers::pi / root);
    const double v = kEiTolerance;
    switch (spec.type) {
        case ShaperType::kZv:
            return normalised({1, k}, {0, 0.5}, period);
        case ShaperType::kZvd:
            return normalised({1, 2 * k, k * k}, {0, 0.5, 1}, period);
        case ShaperType::kMzv: {
            // Impulses a third of a period apart in phase (0.375 of a damped period in time).
            const double km = std::exp(-0.75 * zeta * std::numbers::pi / root);
            const double a1 = 1 - 1 / std::numbers::sqrt2;
            return normalised({a1, (std::numbers::sqrt2 - 1) * km, a1 * km * km}, {0, 0.375, 0.75},
                              period);
        }
        case ShaperType::kEi: {
            const double a1 = 0.25 * (1 + v);
            return normalised({a1, 0.5 * (1 - v) * k, a1 * k * k}, {0, 0.5, 1}, period);
        }
        case ShaperType::kTwoHumpEi: {
            const double v2 = v * v;
            const double x = std::cbrt(v2 * (std::sqrt(1 - v2) + 1));
            const double a1 = (3 * x * x + 2 * x + 3 * v2) / (16 * x);
            const double a2 = (0.5 - a1) * k;
            return normalised({a1, a2, a2 * k, a1 * k * k * k}, {0, 0.5, 1, 1.5}, period);
        }
        case ShaperType::kThreeHumpEi: {
            const double k2 = k * k;
            const double a1 = 0.0625 * (1 + 3 * v + 2 * std::sqrt(2 * (v + 1) * v));
            const double a2 = 0.25 * (1 - v) * k;
            const double a3 = (0.5 * (1 + v) - 2 * a1) * k2;
            return normalised({a1, a2, a3, a2 * k2, a1 * k2 * k2}, {0, 0.5, 1, 1.5, 2}, period);
        }
    }
    throw std::invalid_argument("unknown shaper type");
}

std::vector<ShaperTap> design_shaper_taps(const ShaperSpec& spec, double tick_hz,
                                          std::uint32_t history_ticks) {
    if (!std::isfinite(tick_hz) || tick_hz <= 0)
        throw std::invalid_argument("tick rate must be positive");
    const std::vector<ShaperImpulse> impulses = shaper_impulses(spec);
    const double last = impulses.back().time * tick_hz;
    std::ostringstream why;
    if (last < 2) {
        why << shaper_type_name(spec.type) << " shaper at " << spec.frequency_hz << " Hz lasts "
            << last << " ticks at " << tick_hz
            << " Hz: at least 2 are needed (a lower frequency or a faster tick)";
        throw std::invalid_argument(why.str());
    }
    if (std::ceil(last) >= history_ticks) {
        why << shaper_type_name(spec.type) << " shaper at " << spec.frequency_hz << " Hz lasts "
            << std::ceil(last) << " ticks at " << tick_hz << " Hz: the device remembers "
            << history_ticks - 1 << " (a higher frequency or a slower tick)";
        throw std::invalid_argument(why.str());
    }
    std::map<std::uint32_t, double> split;
    for (const ShaperImpulse& impulse : impulses) {
        const double at = impulse.time * tick_hz;
        const double whole = std::floor(at);
        const double part = at - whole;
        split[static_cast<std::uint32_t>(whole)] += impulse.weight * (1 - part);
        if (part > 0) split[static_cast<std::uint32_t>(whole) + 1] += impulse.weight * part;
    }
    // Largest remainder: floors first, then the missing units to the largest fractions. A tap
    // whose share rounds to nothing is dropped (its weight would be below 2^-16).
    struct Share {
        std::uint32_t delay;
        double exact;
        std::uint32_t units;
    };
    std::vector<Share> shares;
    std::uint64_t total = 0;
    for (const auto& [delay, weight] : split) {
        const double exact = weight * kShaperWeightOne;
        const auto units = static_cast<std::uint32_t>(std::floor(exact));
        shares.push_back({delay, exact, units});
        total += units;
    }
    std::vector<std::size_t> order(shares.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return shares[a].exact - shares[a].units > shares[b].exact - shares[b].units;
    });
    for (std::size_t i = 0; total < kShaperWeightOne; i = (i + 1) % order.size(), ++total)
        ++shares[order[i]].units;
    std::vector<ShaperTap> taps;
    for (const Share& s : shares)
        if (s.units > 0) taps.push_back({s.delay, s.units});
    return taps;
}

double residual_vibration_ratio(const std::vector<ShaperTap>& taps, double tick_hz,
                                double frequency_hz, double damping) {
    if (taps.empty()) return 1;
    const double omega = 2 * std::numbers::pi * frequency_hz;
    const double omega_d = omega * std::sqrt(1 - damping * damping);
    const double t_last = taps.back().delay / tick_hz;
    std::complex<double> sum = 0;
    for (const ShaperTap& tap : taps) {
        const double t = tap.delay / tick_hz;
        const double w = static_cast<double>(tap.weight) / kShaperWeightOne;
        sum += w * std::exp(damping * omega * (t - t_last)) *
               std::complex<double>(std::cos(omega_d * t), std::sin(omega_d * t));
    }
    return std::abs(sum);
}

ShaperSpread shaper_spread(const std::vector<ShaperTap>& taps, double tick_hz) {
    ShaperSpread s;
    if (taps.empty()) return s;
    double mean = 0;
    for (const ShaperTap& t : taps)
        mean += static_cast<double>(t.weight) / kShaperWeightOne * t.delay / tick_hz;
    for (const ShaperTap& t : taps) {
        const double w = static_cast<double>(t.weight) / kShaperWeightOne;
        const double d = t.delay / tick_hz - mean;
        s.variance += w * d * d;
        s.spread += w * std::fabs(d);
    }
    s.longest_delay = taps.back().delay;
    return s;
}

ShaperSpread profile_shaper_spread(const MachineProfile& profile) {
    ShaperSpread most;
    for (const auto& spec : profile.input_shaper) {
        if (!spec) continue;
        const ShaperSpread s = shaper_spread(
            design_shaper_taps(*spec, profile.tick_hz, kDeviceShaperHistoryTicks), profile.tick_hz);
        most.variance = std::max(most.variance, s.variance);
        most.spread = std::max(most.spread, s.spread);
        most.longest_delay = std::max(most.longest_delay, s.longest_delay);
    }
    return most;
}

double shaper_duration(const std::vector<ShaperTap>& taps, double tick_hz) {
    return taps.empty() ? 0 : (taps.back().delay - taps.front().delay) / tick_hz;
}

}  // namespace pathstream::host
