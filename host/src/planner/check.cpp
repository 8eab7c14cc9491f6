// The per-tick check of a plan: every setpoint the core produces, against the machine's
// limits, the geometric path and the pen dwells.
//
// Setpoints come from pathstream::SetpointStream (so every span is validated and continuity is
// enforced exactly as on the device). Velocity of axis i at tick k is the first difference
// (p[k] - p[k-1]) / T, acceleration the second difference (p[k+1] - 2 p[k] + p[k-1]) / T^2; the
// axes rest before tick 0 and after the last tick. Rounding each setpoint once (error in
// (-1/2, 1/2] LSB) moves a first difference by less than 1 LSB and a second difference by less
// than 2 LSB, so a tick is within the limits when |first difference| <= v T / lsb + 1 and
// |second difference| <= a T^2 / lsb + 2 (max_*_fraction subtract exactly this). Those fractions
// come in coarse steps (1/3 of the limit at 3 LSB/tick^2) and stay below the exact cubic's, so
// the check also keeps the raw integer peaks in LSB and the exact fractions for reports.
#include "check.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "cubic.hpp"
#include "jerk_meter.hpp"
#include "path_window.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/core_span.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/span.hpp"
#include "projection.hpp"
#include "vec.hpp"

namespace pathstream::host {
namespace {

using planner_detail::Cubic;
using planner_detail::kAxesMax;
using planner_detail::PathProjector;
using planner_detail::Vec;

/// The exact value (before rounding, LSB) of every axis of one span at tick k (0..ticks): the
/// core's cubic in double,
/// (((a u + b) u + c) u + d) / scale with u = k / ticks, its coefficients converted once for
/// the per-tick check's inner loop.
struct ExactSpan {
    ExactSpan(const CoreSpan& s, std::size_t axes)
        : axes_(axes), ticks_(s.ticks), scale_(basis_matrix(s.basis).scale) {
        for (std::size_t a = 0; a < axes; ++a) {
            const TickCubic& c = s.cubic[a];
            k_[a] = {static_cast<double>(c.a), static_cast<double>(c.b), static_cast<double>(c.c),
                     static_cast<double>(c.d)};
        }
    }
    void at(std::uint32_t k, std::array<double, kAxesMax>& e) const {
        const double u = static_cast<double>(k) / ticks_;
        for (std::size_t a = 0; a < axes_; ++a) {
            const auto& c = k_[a];
            e[a] = (((c[0] * u + c[1]) * u + c[2]) * u + c[3]) / scale_;
        }
    }

    std::size_t axes_;
    double ticks_, scale_;
    std::array<std::array<double, 4>, kAxesMax> k_{};
};

/// Peak |velocity| (LSB/tick) of axis `axis` over span `s` and |acceleration| (LSB/tick^2) at
/// its two ends, from the core's exact cubic p(u) = (a u^3 + b u^2 + c u + d) / scale, u = k/n:
/// the velocity is quadratic (peak at an end or where the acceleration crosses 0), the
/// acceleration linear.
struct SpanPeaks {
    double velocity = 0, acceleration = 0;
};
SpanPeaks span_peaks(const CoreSpan& s, std::size_t axis) {
    const TickCubic& c = s.cubic[axis];
    const double n = s.ticks, scale = basis_matrix(s.basis).scale;
    const double a = static_cast<double>(c.a), b = static_cast<double>(c.b),
                 cc = static_cast<double>(c.c);
    const auto v = [&](double u) { return std::fabs((3 * a * u + 2 * b) * u + cc) / (scale * n); };
    SpanPeaks r;
    r.velocity = std::max(v(0), v(1));
    if (a != 0) {
        const double u = -b / (3 * a);
        if (u > 0 && u < 1) r.velocity = std::max(r.velocity, v(u));
    }
    r.acceleration = std::max(std::fabs(2 * b), std::fabs(6 * a + 2 * b)) / (scale * n * n);
    return r;
}

}  // namespace

namespace planner_detail {

/// Feed requested for a span: its subpath's (pen-down) or travel's (pen-up), else the profile's.
class FeedTable {
public:
    explicit FeedTable(const MachineProfile& profile) : profile_(profile) {}
    void add(const BezierSegment& s) { add(s.subpath, s.pen_down, s.feed); }
    void add(std::size_t subpath, bool pen_down, double feed) {
        if (feed > 0) (pen_down ? down_ : up_).emplace(subpath, feed);
    }
    double feed(const CoreSpan& s) const {
        const auto& m = s.pen_down ? down_ : up_;
        const auto it = m.find(s.subpath);
        if (it != m.end()) return it->second;
        return s.pen_down ? profile_.feed : profile_.travel_feed;
    }

private:
    const MachineProfile& profile_;
    std::map<std::size_t, double> down_, up_;
};

/// The core's setpoint stream for any axis count (SetpointStream is a template on it).
class CoreStepper {
public:
    virtual ~CoreStepper() = default;
    virtual Status push(const CoreSpan& cs, std::uint32_t tag) = 0;
    virtual void tick(std::array<std::int64_t, kAxesMax>& out) = 0;
};

template <unsigned Axes>
class CoreStepperOf : public CoreStepper {
public:
    explicit CoreStepperOf(const CoreSpan& first) {
        Lsb start[Axes];
        for (unsigned a = 0; a < Axes; ++a) start[a] = core_value_at(first, a, 0);
        stream_ = std::make_unique<SetpointStream<Axes, 4>>(start);
    }
    Status push(const CoreSpan& cs, std::uint32_t tag) override {
        Span<Axes> span;
        span.basis = cs.basis;
        span.ticks = cs.ticks;
        span.tag = tag;
        span.outputs = span_outputs(cs);
        for (unsigned a = 0; a < Axes; ++a) {
            for (unsigned k = 0; k < 4; ++k) span.control[a][k] = cs.control[a][k];
        }
        return stream_->push(span);
    }
    void tick(std::array<std::int64_t, kAxesMax>& out) override {
        Lsb v[Axes];
        (void)stream_->tick(v);
        for (unsigned a = 0; a < Axes; ++a) out[a] = v[a];
    }

private:
    std::unique_ptr<SetpointStream<Axes, 4>> stream_;
};

static std::unique_ptr<CoreStepper> make_stepper(std::size_t axes, const CoreSpan& first) {
    switch (axes) {
        case 1:
            return std::make_unique<CoreStepperOf<1>>(first);
        case 2:
            return std::make_unique<CoreStepperOf<2>>(first);
        case 3:
            return std::make_unique<CoreStepperOf<3>>(first);
        case 4:
            return std::make_unique<CoreStepperOf<4>>(first);
        case 5:
            return std::make_unique<CoreStepperOf<5>>(first);
        case 6:
            return std::make_unique<CoreStepperOf<6>>(first);
        case 7:
            return std::make_unique<CoreStepperOf<7>>(first);
        case 8:
            return std::make_unique<CoreStepperOf<8>>(first);
        default:
            throw PlanError("plan check: 1 to 8 axes");
    }
}

TickChecker::TickChecker(const MachineProfile& profile, const std::vector<BezierSegment>* segments,
                         bool deviation)
    : profile_(profile),
      axes_(profile.axes.size()),
      feeds_(std::make_unique<FeedTable>(profile)),
      do_deviation_(deviation && segments != nullptr) {
    if (axes_ == 0 || axes_ > kAxesMax) throw PlanError("plan check: 1 to 8 axes");
    const double t = 1.0 / profile.tick_hz;
    for (std::size_t i = 0; i < axes_; ++i) {
        vlim_[i] = profile.axes[i].max_velocity * t / profile.mm_per_lsb;
        alim_[i] = profile.axes[i].max_acceleration * t * t / profile.mm_per_lsb;
    }
    out_.axis_velocity_fraction.assign(axes_, 0);
    out_.axis_acceleration_fraction.assign(axes_, 0);
    out_.axis_velocity_fraction_exact.assign(axes_, 0);
    out_.axis_acceleration_fraction_exact.assign(axes_, 0);
    out_.axis_max_step.assign(axes_, 0);
    out_.axis_max_second_difference.assign(axes_, 0);
    out_.axis_velocity_limit_lsb.assign(vlim_.begin(),
                                        vlim_.begin() + static_cast<std::ptrdiff_t>(axes_));
    out_.axis_acceleration_limit_lsb.assign(alim_.begin(),
                                            alim_.begin() + static_cast<std::ptrdiff_t>(axes_));
    if (segments != nullptr) {
        for (const BezierSegment& seg : *segments) feeds_->add(seg);
    }
    if (do_deviation_) {
        std::vector<Cubic> down;
        std::vector<std::size_t> index;
        for (std::size_t s = 0; s < segments->size(); ++s) {
            if (!(*segments)[s].pen_down) continue;
            down.push_back(to_cubic((*segments)[s]));
            index.push_back(s);
        }
        // Any distance over half the tolerance is confirmed against every segment.
        projector_ = std::make_unique<PathProjector>(std::move(down), std::move(index),
                                                     0.5 * profile.chord_tolerance);
    }
}

TickChecker::TickChecker(const MachineProfile& profile, SegmentSource& path)
    : TickChecker(profile, nullptr, false) {
    do_deviation_ = true;
    window_ = std::make_unique<PathWindow>(path, 0.5 * profile.chord_tolerance,
                                           [this](const BezierSegment& s) { feeds_->add(s); });
}

TickChecker::~TickChecker() = default;

void TickChecker::note_feed(std::size_t subpath, bool pen_down, double feed) {
    feeds_->add(subpath, pen_down, feed);
}

void TickChecker::pen(const PenEvent& e) {
    const std::uint64_t d =
        delay_ticks(e.down ? profile_.pen_down_delay : profile_.pen_up_delay, profile_.tick_hz);
    if (d > 0) windows_.emplace_back(e.tick, e.tick + d);
    pens_.push_back(e);
}

void TickChecker::span(const CoreSpan& cs) {
    if (cs.control.size() != axes_ || cs.cubic.size() != axes_) {
        throw PlanError("plan check: a span has " + std::to_string(cs.control.size()) +
                        " axes but the machine has " + std::to_string(axes_));
    }
    if (!stepper_) stepper_ = make_stepper(axes_, cs);
    for (std::size_t a = 0; a < axes_; ++a) {
        const SpanPeaks peaks = span_peaks(cs, a);
        const double fv = peaks.velocity / vlim_[a], fa = peaks.acceleration / alim_[a];
        out_.max_span_velocity_fraction = std::max(out_.max_span_velocity_fraction, fv);
        out_.max_span_acceleration_fraction = std::max(out_.max_span_acceleration_fraction, fa);
        out_.axis_velocity_fraction_exact[a] = std::max(out_.axis_velocity_fraction_exact[a], fv);
        out_.axis_acceleration_fraction_exact[a] =
            std::max(out_.axis_acceleration_fraction_exact[a], fa);
    }
    if (const Status st = stepper_->push(cs, static_cast<std::uint32_t>(spans_));
        st != Status::kOk) {
        std::ostringstream m;
        m << "plan check: span " << spans_ << " (subpath " << cs.subpath
          << ") refused by the core: " << status_name(st);
        throw PlanError(m.str());
    }
    ++spans_;
    if (window_) window_->prepare(cs.subpath, cs.pen_down);
    std::array<std::int64_t, kAxesMax> p{};
    std::array<double, kAxesMax> e{};
    const double feed = feeds_->feed(cs);  // once per span, not per tick
    const ExactSpan exact(cs, axes_);
    for (std::uint32_t k = 0; k < cs.ticks; ++k) {
        stepper_->tick(p);
        exact.at(k, e);
        visit(p, e, cs.pen_down, feed);
    }
    // What the held end point after the last span needs (finish), without copying the span.
    exact.at(cs.ticks, last_end_);
    last_pen_down_ = cs.pen_down;
    last_feed_ = feed;
}

void TickChecker::fold_peaks() {
    for (std::size_t a = 0; a < axes_; ++a) {
        const AxisPeaks& k = peaks_[a];
        out_.axis_velocity_fraction[a] =
            std::max(out_.axis_velocity_fraction[a], k.velocity_allowed / vlim_[a]);
        out_.max_velocity_fraction_raw =
            std::max(out_.max_velocity_fraction_raw, k.velocity_raw / vlim_[a]);
        out_.max_velocity_fraction_exact =
            std::max(out_.max_velocity_fraction_exact, k.velocity_exact / vlim_[a]);
        out_.axis_velocity_fraction_exact[a] =
            std::max(out_.axis_velocity_fraction_exact[a], k.velocity_exact / vlim_[a]);
        out_.axis_acceleration_fraction[a] =
            std::max(out_.axis_acceleration_fraction[a], k.acceleration_allowed / alim_[a]);
        out_.max_acceleration_fraction_raw =
            std::max(out_.max_acceleration_fraction_raw, k.acceleration_raw / alim_[a]);
        out_.max_acceleration_fraction_exact =
            std::max(out_.max_acceleration_fraction_exact, k.acceleration_exact / alim_[a]);
        out_.axis_acceleration_fraction_exact[a] =
            std::max(out_.axis_acceleration_fraction_exact[a], k.acceleration_exact / alim_[a]);
    }
}

bool TickChecker::over_limits() {
    fold_peaks();
    for (std::size_t a = 0; a < axes_; ++a) {
        if (out_.axis_velocity_fraction[a] > 1 || out_.axis_acceleration_fraction[a] > 1)
            return true;
    }
    return out_.max_velocity_fraction_exact > 1 || out_.max_acceleration_fraction_exact > 1 ||
           out_.max_span_velocity_fraction > 1 || out_.max_span_acceleration_fraction > 1;
}

bool TickChecker::pen_down_at(std::uint64_t tick) {
    while (pen_index_ < pens_.size() && pens_[pen_index_].tick <= tick) {
        pen_down_ = pens_[pen_index_].down;
        ++pen_index_;
    }
    return pen_down_;
}

bool TickChecker::in_window(std::uint64_t tick) {
    while (window_index_ < windows_.size() && windows_[window_index_].second <= tick)
        ++window_index_;
    return window_index_ < windows_.size() && windows_[window_index_].first <= tick;
}

void TickChecker::visit(const std::array<std::int64_t, kAxesMax>& p,
                        const std::array<double, kAxesMax>& e, bool pen_output, double feed) {
    const std::uint64_t k = tick_;
    if (observer_) observer_(k, p.data(), pen_output);
    if (k == 0) {  // at rest before the first tick
        p1_ = p2_ = p;
        e1_ = e2_ = e;
    }
    // First difference p[k] - p[k-1] (motion during tick k-1, inside the previous tick's span).
    bool moved = false;
    double speed2 = 0;
    for (std::size_t a = 0; a < axes_; ++a) {
        const std::int64_t step = p[a] - p1_[a];
        const double d = static_cast<double>(step);
        const double de = e[a] - e1_[a];
        if (d != 0) moved = true;
        speed2 += d * d;
        out_.axis_max_step[a] = std::max(out_.axis_max_step[a], step < 0 ? -step : step);
        velocity(a, std::fabs(d), std::fabs(de));
    }
    if (k > 0 && moved && in_window(k - 1)) out_.drawing_while_pen_moves = true;
    if (k > 0 && moved && have_prev_span_) {
        const double lsb_per_tick = profile_.mm_per_lsb * profile_.tick_hz;
        // Allowance: each setpoint's rounding (< 1 LSB per axis in a difference) and the
        // rounding of the spans' end points and tangents (about as much again).
        const double speed =
            std::max(0.0, std::sqrt(speed2) - 2 * std::sqrt(static_cast<double>(axes_))) *
            lsb_per_tick;
        out_.max_feed_fraction = std::max(out_.max_feed_fraction, speed / prev_feed_);
    }
    // Second difference centred on k - 1.
    if (k > 0) {
        for (std::size_t a = 0; a < axes_; ++a) {
            acceleration(a, p[a] - 2 * p1_[a] + p2_[a], std::fabs(e[a] - 2 * e1_[a] + e2_[a]));
        }
    }
    // Deviation of a pen-down setpoint.
    const bool down = pen_down_at(k);
    if (!down) have_distance_ = false;
    PathProjector* const projector = window_ ? window_->projector() : projector_.get();
    if (do_deviation_ && down && projector != nullptr && !projector->empty()) {
        if (k == 0 || moved || !have_distance_) {
            Vec q{};
            for (std::size_t a = 0; a < axes_; ++a)
                q[a] = static_cast<double>(p[a]) * profile_.mm_per_lsb;
            // Only the largest distance matters: the exact search runs where the cheap bound
            // could pass it.
            distance_ = projector->follow(q);
            if (distance_ > out_.max_deviation) {
                std::size_t seg = 0;
                distance_ = projector->distance(q, seg);
            }
            have_distance_ = true;
        }
        if (distance_ > out_.max_deviation) {
            out_.max_deviation = distance_;
            out_.worst_deviation_tick = k;
        }
    }
    p2_ = p1_;
    p1_ = p;
    e2_ = e1_;
    e1_ = e;
    prev_feed_ = feed;
    have_prev_span_ = true;
    ++tick_;
}

void TickChecker::velocity(std::size_t a, double d, double de) {
    AxisPeaks& k = peaks_[a];
    k.velocity_allowed = std::max(k.velocity_allowed, std::max(0.0, d - 1));
    k.velocity_raw = std::max(k.velocity_raw, d);
    k.velocity_exact = std::max(k.velocity_exact, de);
}

void TickChecker::acceleration(std::size_t a, std::int64_t second, double de) {
    const std::int64_t magnitude = second < 0 ? -second : second;
    out_.axis_max_second_difference[a] = std::max(out_.axis_max_second_difference[a], magnitude);
    const double d = static_cast<double>(magnitude);
    AxisPeaks& k = peaks_[a];
    k.acceleration_allowed = std::max(k.acceleration_allowed, std::max(0.0, d - 2));
    k.acceleration_raw = std::max(k.acceleration_raw, d);
    k.acceleration_exact = std::max(k.acceleration_exact, de);
}

PlanCheck TickChecker::finish() {
    if (spans_ == 0) {
        out_.within_limits = true;
        return out_;
    }
    // The end point, held: the idle tick after the last span.
    std::array<std::int64_t, kAxesMax> p{};
    std::array<double, kAxesMax> e{};
    stepper_->tick(p);
    for (std::size_t a = 0; a < axes_; ++a) e[a] = last_end_[a];
    visit(p, e, last_pen_down_, last_feed_);
    // The axes rest after the end: one more second difference, centred on the end point.
    for (std::size_t a = 0; a < axes_; ++a)
        acceleration(a, p2_[a] - p1_[a], std::fabs(e2_[a] - e1_[a]));
    fold_peaks();
    for (std::size_t a = 0; a < axes_; ++a) {
        out_.max_velocity_fraction =
            std::max(out_.max_velocity_fraction, out_.axis_velocity_fraction[a]);
        out_.max_acceleration_fraction =
            std::max(out_.max_acceleration_fraction, out_.axis_acceleration_fraction[a]);
    }
    // The exact cubic must be within the limits too (a device that validates spans refuses
    // anything over), not only the rounded setpoints with their allowance.
    out_.within_limits =
        out_.max_velocity_fraction <= 1 && out_.max_acceleration_fraction <= 1 &&
        out_.max_velocity_fraction_exact <= 1 && out_.max_acceleration_fraction_exact <= 1 &&
        out_.max_span_velocity_fraction <= 1 && out_.max_span_acceleration_fraction <= 1;
    out_.ticks_checked = tick_;
    return out_;
}

PlanCheck check_plan_impl(const Plan& plan, const std::vector<BezierSegment>& segments,
                          const MachineProfile& profile, bool deviation) {
    TickChecker checker(profile, &segments, deviation);
    JerkMeter jerk(profile);
    for (const PenEvent& e : plan.pen) checker.pen(e);
    for (const CoreSpan& s : plan.spans) {
        checker.span(s);
        jerk.span(s);
    }
    PlanCheck out = checker.finish();
    jerk.finish(out);
    return out;
}
}  // namespace planner_detail

PlanCheck check_plan(const Plan& plan, const std::vector<BezierSegment>& segments,
                     const MachineProfile& profile) {
    return planner_detail::check_plan_impl(plan, segments, profile, true);
}

}  // namespace pathstream::host

namespace pathstream::host {

PlanChecker::PlanChecker(const std::vector<BezierSegment>& segments, const MachineProfile& profile)
    : impl_(std::make_unique<planner_detail::TickChecker>(profile, &segments, true)),
      jerk_(std::make_unique<planner_detail::JerkMeter>(profile)) {}

PlanChecker::PlanChecker(SegmentSource& path, const MachineProfile& profile)
    : impl_(std::make_unique<planner_detail::TickChecker>(profile, path)),
      jerk_(std::make_unique<planner_detail::JerkMeter>(profile)) {}

PlanChecker::~PlanChecker() = default;

void PlanChecker::span(const CoreSpan& s) {
    impl_->span(s);
    jerk_->span(s);
    ++spans_;
    ticks_ += s.ticks;
}

void PlanChecker::pen(const PenEvent& e) {
    impl_->pen(e);
    ++pens_;
}

void PlanChecker::on_tick(std::function<void(std::uint64_t, const std::int64_t*, bool)> observer) {
    impl_->observe(std::move(observer));
}

PlanCheck PlanChecker::finish() {
    PlanCheck out = impl_->finish();
    jerk_->finish(out);
    return out;
}

}  // namespace pathstream::host
