#include "jerk_meter.hpp"

#include <algorithm>
#include <cmath>

namespace pathstream::host::planner_detail {

JerkMeter::JerkMeter(const MachineProfile& profile)
    : profile_(profile),
      axes_(profile.axes.size()),
      jerk_lsb_(axes_, 0),
      step_lsb_(axes_, 0),
      limit_lsb_(axes_, 0),
      previous_end_(axes_) {
    const double t = 1.0 / profile.tick_hz;
    for (std::size_t a = 0; a < axes_; ++a)
        limit_lsb_[a] = profile.axes[a].max_jerk * t * t * t / profile.mm_per_lsb;
}

// |next - previous| in LSB/tick^2, from the two fractions cross-multiplied exactly (each
// numerator < 2^36, denominator < 2^35) and divided once.
void JerkMeter::join(std::size_t axis, const Acceleration& next, const Acceleration& previous,
                     std::vector<double>& step) const {
    const __int128 difference =
        static_cast<__int128>(next.numerator) * static_cast<__int128>(previous.denominator) -
        static_cast<__int128>(previous.numerator) * static_cast<__int128>(next.denominator);
    const long double magnitude =
        static_cast<long double>(difference < 0 ? -difference : difference) /
        (static_cast<long double>(next.denominator) *
         static_cast<long double>(previous.denominator));
    step[axis] = std::max(step[axis], static_cast<double>(magnitude));
}

void JerkMeter::span(const CoreSpan& s) {
    const std::uint64_t n = s.ticks;
    const std::uint64_t scale = basis_matrix(s.basis).scale;
    for (std::size_t a = 0; a < axes_ && a < s.cubic.size(); ++a) {
        const TickCubic& c = s.cubic[a];
        // p(u) = (a u^3 + b u^2 + c u + d) / s, u = k/n: jerk 6a / (s n^3) LSB/tick^3, and the
        // acceleration 2b / (s n^2) at the start, (6a + 2b) / (s n^2) at the end.
        const long double jerk =
            std::fabs(static_cast<long double>(6 * c.a)) /
            (static_cast<long double>(scale) * static_cast<long double>(n * n * n));
        jerk_lsb_[a] = std::max(jerk_lsb_[a], static_cast<double>(jerk));
        const Acceleration start{2 * c.b, scale * n * n};
        join(a, start, previous_end_[a], step_lsb_);
        previous_end_[a] = Acceleration{6 * c.a + 2 * c.b, scale * n * n};
        if (s.pause_after) {
            join(a, Acceleration{}, previous_end_[a], step_lsb_);
            previous_end_[a] = Acceleration{};
        }
    }
    any_span_ = true;
}

void JerkMeter::finish(PlanCheck& out) const {
    std::vector<double> step = step_lsb_;
    if (any_span_) {
        for (std::size_t a = 0; a < axes_; ++a) join(a, Acceleration{}, previous_end_[a], step);
    }
    const double hz = profile_.tick_hz, lsb = profile_.mm_per_lsb;
    out.jerk_limited = false;
    out.axis_jerk_lsb = jerk_lsb_;
    out.axis_join_acceleration_step_lsb = step;
    out.axis_jerk_limit_lsb = limit_lsb_;
    out.axis_jerk.assign(axes_, 0);
    out.axis_join_acceleration_step.assign(axes_, 0);
    out.axis_jerk_fraction_exact.assign(axes_, 0);
    out.axis_join_acceleration_step_fraction.assign(axes_, 0);
    out.max_jerk_fraction_exact = out.max_join_acceleration_step_fraction = 0;
    for (std::size_t a = 0; a < axes_; ++a) {
        out.axis_jerk[a] = jerk_lsb_[a] * hz * hz * hz * lsb;
        out.axis_join_acceleration_step[a] = step[a] * hz * hz * lsb;
        if (limit_lsb_[a] <= 0) continue;
        out.jerk_limited = true;
        // A join may step by one tick of jerk: J * 1 tick, in LSB/tick^2 the same number as J.
        out.axis_jerk_fraction_exact[a] = jerk_lsb_[a] / limit_lsb_[a];
        out.axis_join_acceleration_step_fraction[a] = step[a] / limit_lsb_[a];
        out.max_jerk_fraction_exact =
            std::max(out.max_jerk_fraction_exact, out.axis_jerk_fraction_exact[a]);
        out.max_join_acceleration_step_fraction = std::max(
            out.max_join_acceleration_step_fraction, out.axis_join_acceleration_step_fraction[a]);
    }
    if (out.max_jerk_fraction_exact > 1 || out.max_join_acceleration_step_fraction > 1)
        out.within_limits = false;
}

}  // namespace pathstream::host::planner_detail
