// The device's general rest-to-rest move of one axis, planned on the device in integers: what a
// homing search, its back-off and approach, and an operator's jog are made of. Each move is a
// trapezoid of constant-acceleration Hermite spans (cubic term exactly zero), or under a jerk
// limit an S-curve of exact cubics (s_curve_ramp.hpp), so the device's exact limit check passes
// them like any planned span (docs/gpio.md, docs/device.md).
#pragma once

#include <cstdint>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/device/s_curve_ramp.hpp"
#include "pathstream/device/stop_spans.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/units.hpp"

namespace pathstream::device {

/// A rest-to-rest move of one axis: ramp up, cruise, ramp down, and (for the remainder the
/// ramps cannot cover exactly) one short rest-to-rest creep span. Without a jerk limit the
/// ramps are constant-acceleration spans (even tangents, so every end point is an exact
/// integer); under one, S-curves (SCurveRamp: the acceleration ramped at up to the jerk limit
/// to up to the axis's acceleration limit, continuous at every knot, exact integers too).
/// Freestanding, no heap.
template <unsigned Axes>
class AxisMove {
public:
    AxisMove() = default;

    /// Plans `distance` LSB (signed) on `axis` from `start` at up to `velocity` LSB/s within
    /// `limits`, its jerk limit included (the device checks the spans like a host's).
    /// kBadLimits when no span length gives a usable acceleration step or the creep
    /// span fits the limits at no length: every span is settled here, so next() cannot fail
    /// half-way through a move (a jog refused after some of its spans were queued would leave
    /// the device changed by a refused command).
    [[nodiscard]] Status plan(const Lsb (&start)[Axes], unsigned axis, std::int64_t distance,
                              std::uint32_t velocity, const MotionLimits<Axes>& limits) {
        for (unsigned a = 0; a < Axes; ++a) at_[a] = start[a];
        axis_ = axis;
        sign_ = distance < 0 ? -1 : 1;
        remaining_ = distance < 0 ? -distance : distance;
        limits_ = limits;
        index_ = 0;
        const std::uint64_t hz = limits.tick_hz;
        if (hz == 0) return Status::kBadLimits;
        s_curve_ = false;
        if (limits.axis[axis].max_jerk != 0) {
            cap_by_jerk(limits);
            if (const Status st = plan_s_curve(start, velocity, limits); st != Status::kBadLimits)
                return st;
            // No S-curve span length fits these limits: the constant-acceleration ramps below,
            // on limits_ as capped.
        }
        const AxisLimits& l = limits_.axis[axis];
        if (velocity > l.max_velocity) velocity = l.max_velocity;
        // Span length n: the smallest power of two whose per-span tangent step a n^2 / hz^2
        // is at least 2 (tangents stay even); at least 8 ticks.
        n_ = 8;
        while (static_cast<std::uint64_t>(l.max_acceleration) * n_ * n_ < 2 * hz * hz) {
            n_ *= 2;
            if (n_ > kMaxSpanTicks / 2) return Status::kBadLimits;
        }
        step_ = even_floor(static_cast<std::uint64_t>(l.max_acceleration) * n_ * n_ / (hz * hz));
        cruise_ = even_floor(static_cast<std::uint64_t>(velocity) * n_ / hz);
        if (cruise_ < 2) cruise_ = 2;
        while (static_cast<std::uint64_t>(cruise_) * hz >
                   static_cast<std::uint64_t>(l.max_velocity) * n_ &&
               cruise_ > 2) {
            cruise_ -= 2;
        }
        // Even the slowest cruise (2 LSB per span) is over the velocity limit: the device would
        // refuse every span, so the move is refused here.
        if (static_cast<std::uint64_t>(cruise_) * hz >
            static_cast<std::uint64_t>(l.max_velocity) * n_) {
            return Status::kBadLimits;
        }
        // Shrink the cruise tangent until both ramps fit in the distance. A ramp of R spans
        // to tangent c covers at least R (c/2 - 2) (every rounded tangent is within 2 of
        // c i / R): a cruise that cannot fit by that bound is halved without summing its
        // spans, so the sum runs only for R (c - 4) <= distance: R <= 11,586 for a jog's
        // largest distance, 2^28 LSB, whatever the limits (it was a loop of 10^8 spans).
        for (;;) {
            ramp_spans_ = static_cast<std::uint32_t>((cruise_ + step_ - 1) / step_);
            const std::uint64_t least = static_cast<std::uint64_t>(ramp_spans_) *
                                        static_cast<std::uint64_t>(cruise_ > 4 ? cruise_ - 4 : 0);
            if (least > static_cast<std::uint64_t>(remaining_)) {
                cruise_ = even_floor(static_cast<std::uint64_t>(cruise_) / 2);
                if (cruise_ < 2) cruise_ = 2;
                continue;
            }
            ramp_distance_ = 0;
            for (std::uint32_t i = 0; i < ramp_spans_; ++i)
                ramp_distance_ += (ramp_tangent(i) + ramp_tangent(i + 1)) / 2;
            if (2 * ramp_distance_ <= remaining_ || cruise_ <= 2) break;
            cruise_ = even_floor(static_cast<std::uint64_t>(cruise_) / 2);
            if (cruise_ < 2) cruise_ = 2;
        }
        if (2 * ramp_distance_ > remaining_) {
            ramp_spans_ = 0;
            ramp_distance_ = 0;
        }
        const std::int64_t middle = remaining_ - 2 * ramp_distance_;
        cruise_spans_ = ramp_spans_ == 0 ? 0 : middle / cruise_;
        creep_ = ramp_spans_ == 0 ? middle : middle % cruise_;
        creep_ticks_ = 0;
        if (creep_ != 0) {
            const std::int64_t creep_from = start[axis] + sign_ * (remaining_ - creep_);
            if (creep_from > kMaxPositionLsb || creep_from < -kMaxPositionLsb) {
                return Status::kBadLimits;
            }
            creep_ticks_ = creep_length(static_cast<Lsb>(creep_from));
            if (creep_ticks_ == 0) return Status::kBadLimits;
        }
        return Status::kOk;
    }

    /// True while spans remain.
    bool pending() const { return index_ < total_spans(); }

    /// Writes the next span (absolute end point, explicit tangents, pen up). False only when
    /// the move is complete.
    bool next(WireSpan& w) {
        if (!pending()) return false;
        w = WireSpan{};
        const std::int64_t i = index_;
        const std::int64_t ramps = ramp_spans_;
        std::int64_t t0 = 0, t1 = 0;
        w.ticks = n_;
        if (s_curve_ && i < 2 * ramps + cruise_spans_) {
            std::int64_t chord = cruise_;
            t0 = t1 = cruise_;
            if (i >= ramps && i < ramps + 3 * dips_) {  // a dip of x: knots 0, -x, x, 0
                const std::int64_t c = i - ramps, x = dip(c / 3), half = x / 2;
                const std::int64_t part = c % 3;
                t0 = part == 0 ? cruise_ : cruise_ - half;
                t1 = part == 2 ? cruise_ : cruise_ - half;
                chord = part == 1 ? cruise_ - half - x / 6 : cruise_ - x / 6;
            } else if (i < ramps) {  // up: knot k = i to k + 1, T walking up from 0
                const auto k = static_cast<std::uint32_t>(i);
                const std::int64_t a0 = ramp_.at(k), a1 = ramp_.at(k + 1);
                t0 = walk_;
                t1 = walk_ + (a0 + a1) / 2;
                chord = t0 + (2 * a0 + a1) / 6;
                walk_ = t1;
            } else if (i >= ramps + cruise_spans_) {  // down: the up span k played backwards
                const auto k = static_cast<std::uint32_t>(2 * ramps + cruise_spans_ - 1 - i);
                const std::int64_t a0 = ramp_.at(k), a1 = ramp_.at(k + 1);
                if (i == ramps + cruise_spans_) walk_ = cruise_;
                t0 = walk_;
                t1 = walk_ - (a0 + a1) / 2;
                chord = t1 + (2 * a0 + a1) / 6;
                walk_ = t1;
            }
            at_[axis_] = static_cast<Lsb>(at_[axis_] + sign_ * chord);
            fill(w, static_cast<std::int32_t>(sign_ * t0), static_cast<std::int32_t>(sign_ * t1));
            ++index_;
            return true;
        }
        if (i < ramps) {
            t0 = ramp_tangent(static_cast<std::uint32_t>(i));
            t1 = ramp_tangent(static_cast<std::uint32_t>(i + 1));
        } else if (i < ramps + cruise_spans_) {
            t0 = t1 = cruise_;
        } else if (i < 2 * ramps + cruise_spans_) {
            const std::int64_t k = 2 * ramps + cruise_spans_ - i;  // ramp_spans_ .. 1
            t0 = ramp_tangent(static_cast<std::uint32_t>(k));
            t1 = ramp_tangent(static_cast<std::uint32_t>(k - 1));
        } else {
            at_[axis_] = static_cast<Lsb>(at_[axis_] + sign_ * creep_);
            w.ticks = creep_ticks_;
            fill(w, 0, 0);
            ++index_;
            return true;
        }
        const std::int64_t delta = (t0 + t1) / 2;
        at_[axis_] = static_cast<Lsb>(at_[axis_] + sign_ * delta);
        fill(w, static_cast<std::int32_t>(sign_ * t0), static_cast<std::int32_t>(sign_ * t1));
        ++index_;
        return true;
    }

    /// Span length used by the ramps and the cruise.
    std::uint32_t span_ticks() const { return n_; }

private:
    static std::int64_t even_floor(std::uint64_t v) {
        return static_cast<std::int64_t>(v & ~std::uint64_t{1});
    }

    // Tangent after i ramp spans: i/ramp_spans of the cruise tangent, rounded to even.
    std::int64_t ramp_tangent(std::uint32_t i) const {
        if (i >= ramp_spans_) return cruise_;
        return even_floor(static_cast<std::uint64_t>(cruise_) * i / ramp_spans_);
    }

    std::int64_t total_spans() const {
        return 2 * static_cast<std::int64_t>(ramp_spans_) + cruise_spans_ + (creep_ != 0 ? 1 : 0);
    }

    // The cruise between the S-curve ramps: `spans` spans of tangent `cruise` covering `middle`
    // LSB, the first 3 * dips of them dipping (knots 0, -x, x, 0 of A: the tangent falls by
    // x/2 and comes back, and the three spans cover x less than the plain cruise's), the
    // dips' x summing to dip_total, and a creep span of `creep` (< 6) LSB at rest at the end.
    // One cruise span more than middle / cruise and dips for the rest of it, so the creep is
    // the remainder modulo 6 only; where the dips do not fit (too few spans, or a step below
    // 12), the plain cruise and the whole remainder as the creep.
    struct Middle {
        std::int64_t spans = 0, dips = 0, dip_total = 0, creep = 0;
    };
    static Middle plan_middle(std::int64_t middle, std::int64_t cruise, std::int64_t step) {
        Middle m;
        m.spans = middle / cruise;
        m.creep = middle % cruise;
        const std::int64_t highest = step / 12 * 6;  // x <= step / 2: the knots -x, x differ by 2x
        if (m.creep == 0 || highest < 6) return m;
        const std::int64_t total = (cruise - m.creep + 5) / 6 * 6;  // what the dips take off
        const std::int64_t dips = (total + highest - 1) / highest;
        if (3 * dips > m.spans + 1) return m;
        m.spans += 1;
        m.dips = dips;
        m.dip_total = total;
        m.creep = total - (cruise - m.creep);  // the remainder modulo 6
        return m;
    }

    // The depth x of dip g (0 .. dips_ - 1): dip_total_ shared out in multiples of 6.
    std::int64_t dip(std::int64_t g) const {
        const std::int64_t units = dip_total_ / 6, base = units / dips_, extra = units % dips_;
        return 6 * (base + (g < extra ? 1 : 0));
    }

    // Spans an S-curve ramp may have (a slower cruise is planned where it would need more).
    static constexpr std::uint32_t kMaxRampSpans = 1024;

    // The distance of `ramp` planned for `cruise` (its spans' chords summed), or -1 when it has
    // more spans than kMaxRampSpans or the move's distance (its chords average at least 1).
    std::int64_t ramp_distance(std::int64_t cruise, SCurveRamp& ramp) const {
        ramp.plan(cruise);
        if (ramp.spans > kMaxRampSpans || static_cast<std::int64_t>(ramp.spans) > remaining_)
            return -1;
        std::int64_t t = 0, distance = 0;
        for (std::uint32_t k = 0; k < ramp.spans; ++k) {
            const std::int64_t a0 = ramp.at(k), a1 = ramp.at(k + 1);
            distance += t + (2 * a0 + a1) / 6;
            t += (a0 + a1) / 2;
        }
        return distance;
    }

    // Ticks a creep span of `rest` LSB needs at J/2 * 1 tick of acceleration (its ends' 6 rest /
    // m^2 <= J / 2: m >= sqrt(12 rest hz^3 / J)), the other limits aside: where creep_length
    // starts, and an estimate for choosing the cruise.
    std::uint64_t creep_estimate(std::uint64_t rest, const MotionLimits<Axes>& limits) const {
        if (rest == 0) return 0;
        const std::uint64_t hz = limits.tick_hz;
        // 12 rest hz^3 (< 2^35 2^51) over J (>= 100).
        const FloorDivision q =
            floor_divide(multiply_unsigned(12 * rest, hz * hz * hz),
                         std::uint64_t{limits.axis[axis_].max_jerk} * kJerkUnitLsb);
        if (q.quotient.hi != 0) return std::uint64_t{1} << 32;
        std::uint64_t x = q.quotient.lo, root = 0, bit = std::uint64_t{1} << 62;
        while (bit > x) bit >>= 2;
        for (; bit != 0; bit >>= 2) {  // digit by digit
            if (x >= root + bit) {
                x -= root + bit;
                root = (root >> 1) + bit;
            } else {
                root >>= 1;
            }
        }
        return root + 1 < kMaxSpanTicks ? root + 1 : kMaxSpanTicks;
    }

    // limits_ under a jerk limit J: the axis's acceleration at most J/2 * 1 tick, for the spans
    // that step it at their joins (the creep span from and to rest; under a jerk limit with no
    // S-curve, every constant-acceleration span: ramp to ramp, rest to ramp, ramp up to ramp
    // down), so that every step is at most one tick of jerk and the spans carry no jerk.
    void cap_by_jerk(const MotionLimits<Axes>& limits) {
        const std::uint64_t by_jerk = static_cast<std::uint64_t>(limits.axis[axis_].max_jerk) *
                                      kJerkUnitLsb / (2 * std::uint64_t{limits.tick_hz});
        if (by_jerk < limits_.axis[axis_].max_acceleration) {
            limits_.axis[axis_].max_acceleration = static_cast<std::uint32_t>(by_jerk);
        }
    }

    // The S-curve move (SCurveRamp) on limits with a jerk limit on the axis: spans of n ticks,
    // the shortest power of two (from 8) on which the jerk and the acceleration limits give
    // steps of at least 6 in span units (J n^3 >= 6, A n^2 >= 6); the cruise tangent a multiple
    // of 6 at most the requested velocity (n longer where that needs it), as fast as the
    // distance allows (else the creep span alone). kBadLimits (and the constant-acceleration
    // move is planned instead) when no span length fits, or the creep span fits at no length.
    Status plan_s_curve(const Lsb (&start)[Axes], std::uint32_t velocity,
                        const MotionLimits<Axes>& limits) {
        const AxisLimits& l = limits.axis[axis_];
        const std::uint64_t hz = limits.tick_hz;
        if (velocity > l.max_velocity) velocity = l.max_velocity;
        std::uint32_t n = 8;
        std::int64_t step = 0, peak = 0;
        for (;; n *= 2) {
            if (n > kMaxSpanTicks / 2) return Status::kBadLimits;
            // J n^3 = max_jerk 100 n^3 / hz^3 (< 2^39 2^45 over > 2^0); A n^2 = max_acceleration
            // n^2 / hz^2.
            const std::uint64_t n3 = std::uint64_t{n} * n * n;
            const FloorDivision j = floor_divide(
                multiply_unsigned(std::uint64_t{l.max_jerk} * kJerkUnitLsb, n3), 6 * hz * hz * hz);
            const FloorDivision a = floor_divide(
                multiply_unsigned(l.max_acceleration, std::uint64_t{n} * n), 6 * hz * hz);
            constexpr std::uint64_t kLarge = std::uint64_t{1} << 40;  // beyond any tangent's reach
            const std::uint64_t js =
                j.quotient.hi != 0 || j.quotient.lo > kLarge ? kLarge : j.quotient.lo;
            const std::uint64_t as =
                a.quotient.hi != 0 || a.quotient.lo > kLarge ? kLarge : a.quotient.lo;
            // The cruise tangent, a multiple of 6, must not exceed the requested velocity (a
            // homing latch defines zero at its speed): spans long enough for 6 LSB at it.
            if (js >= 1 && as >= 1 && std::uint64_t{velocity} * n >= 6 * hz) {
                step = 6 * static_cast<std::int64_t>(js);
                peak = 6 * static_cast<std::int64_t>(as);
                break;
            }
        }
        // SCurveRamp's range: step <= peak <= step 2^20 (more than 2^20 levels up to the peak
        // fits no ramp of kMaxRampSpans spans anyway).
        if (step > peak) step = peak;
        if (peak / step > (std::int64_t{1} << 20)) peak = step << 20;
        n_ = n;
        ramp_.step = step;
        ramp_.peak = peak;
        std::int64_t cruise =
            static_cast<std::int64_t>(std::uint64_t{velocity} * n / hz / 6 * 6);  // >= 6
        // The fastest cruise whose two ramps fit the distance (a ramp's distance grows with its
        // cruise: bisection over the multiples of 6), then, within 1/8 of it, the one whose move
        // takes the fewest ticks with the creep span's estimated (at most 16 tries): the creep
        // starts and ends at rest at J/2 * 1 tick of acceleration, slow for a long remainder.
        // Bounded work for any limits: at most 47 ramps of at most kMaxRampSpans spans summed.
        const auto fitting = [&](std::int64_t units, SCurveRamp& ramp) -> std::int64_t {
            ramp = ramp_;
            const std::int64_t d = ramp_distance(6 * units, ramp);
            return d >= 0 && 2 * d <= remaining_ ? d : -1;
        };
        SCurveRamp ramp = ramp_;
        std::int64_t top = cruise / 6;
        std::int64_t distance = fitting(1, ramp);
        if (distance < 0) {
            top = 0;  // not even the slowest ramps fit: the creep span alone
        } else {
            std::int64_t low = 1;
            while (low < top) {
                const std::int64_t mid = low + (top - low + 1) / 2;
                if (fitting(mid, ramp) >= 0) {
                    low = mid;
                } else {
                    top = mid - 1;
                }
            }
            std::uint64_t best = ~std::uint64_t{0};
            for (std::int64_t units = top, tries = 0;
                 units >= 1 && units >= top - top / 8 && tries < 16; --units, ++tries) {
                const std::int64_t d = fitting(units, ramp);
                if (d < 0) continue;
                const Middle m = plan_middle(remaining_ - 2 * d, 6 * units, ramp.step);
                const std::uint64_t ticks =
                    (2 * std::uint64_t{ramp.spans} + static_cast<std::uint64_t>(m.spans)) * n_ +
                    creep_estimate(static_cast<std::uint64_t>(m.creep), limits);
                if (ticks < best) {
                    best = ticks;
                    cruise = 6 * units;
                    distance = d;
                    ramp_ = ramp;
                }
            }
        }
        cruise_ = top == 0 ? 6 : cruise;
        if (top == 0) {
            ramp_spans_ = 0;
            ramp_distance_ = 0;
        } else {
            ramp_spans_ = ramp_.spans;
            ramp_distance_ = distance;
        }
        const std::int64_t middle = remaining_ - 2 * ramp_distance_;
        dips_ = dip_total_ = 0;
        if (ramp_spans_ == 0) {
            cruise_spans_ = 0;
            creep_ = middle;
        } else {
            const Middle m = plan_middle(middle, cruise_, ramp_.step);
            cruise_spans_ = m.spans;
            dips_ = m.dips;
            dip_total_ = m.dip_total;
            creep_ = m.creep;
        }
        creep_ticks_ = 0;
        walk_ = 0;
        if (creep_ != 0) {
            const std::int64_t creep_from = start[axis_] + sign_ * (remaining_ - creep_);
            if (creep_from > kMaxPositionLsb || creep_from < -kMaxPositionLsb)
                return Status::kBadLimits;
            creep_ticks_ = creep_length(static_cast<Lsb>(creep_from),
                                        creep_estimate(static_cast<std::uint64_t>(creep_), limits));
            if (creep_ticks_ == 0) return Status::kBadLimits;
        }
        s_curve_ = true;
        return Status::kOk;
    }

    void fill(WireSpan& w, std::int32_t t0, std::int32_t t1) const {
        for (unsigned a = 0; a < Axes; ++a) w.end[a] = at_[a];
        w.start_tangent[axis_] = t0;
        w.end_tangent[axis_] = t1;
    }

    // Ticks of the remainder at rest from `from` (P1 = P0 + creep, T0 = T1 = 0): the first
    // of n, 2n, 4n .. that passes the limits (the move's acceleration, the jerk inside); 0
    // when none up to kMaxSpanTicks does.
    // `first` (S-curve moves: the bound of creep_estimate): the lengths tried are first,
    // first + 1, first + 2, first + 4 .. instead.
    std::uint32_t creep_length(Lsb from, std::uint64_t first = 0) const {
        Span<Axes> s;
        s.basis = Basis::kHermite;
        for (unsigned a = 0; a < Axes; ++a) {
            s.control[a][0] = s.control[a][1] = a == axis_ ? from : at_[a];
            s.control[a][2] = s.control[a][3] = 0;
        }
        s.control[axis_][1] = static_cast<Lsb>(from + sign_ * creep_);
        std::uint64_t step = 0;
        for (std::uint64_t ticks = first != 0 ? first : n_; ticks <= kMaxSpanTicks;
             first != 0 ? (ticks += step == 0 ? 1 : step, step = step == 0 ? 1 : 2 * step)
                        : ticks *= 2) {
            s.ticks = static_cast<std::uint32_t>(ticks);
            ValidatedSpan<Axes> v;
            if (validate_span(s, v) != Status::kOk) continue;
            bool fits = true;
            for (unsigned a = 0; a < Axes && fits; ++a) {
                const AxisLimits& l = limits_.axis[a];
                fits = check_axis_limits(v.cubic[a], v.timing, l, limits_.tick_hz) == Status::kOk &&
                       check_axis_jerk(v.cubic[a], v.timing, l, limits_.tick_hz) == Status::kOk;
            }
            if (fits) return static_cast<std::uint32_t>(ticks);
        }
        return 0;
    }

    Lsb at_[Axes] = {};
    unsigned axis_ = 0;
    std::int64_t sign_ = 1;
    std::int64_t remaining_ = 0;
    MotionLimits<Axes> limits_;
    std::uint32_t n_ = 8;
    std::int64_t step_ = 2;
    std::int64_t cruise_ = 2;
    std::uint32_t ramp_spans_ = 0;
    std::int64_t ramp_distance_ = 0;
    std::int64_t cruise_spans_ = 0;
    std::int64_t creep_ = 0;
    std::uint32_t creep_ticks_ = 0;  // length of the creep span, settled by plan()
    std::int64_t index_ = 0;
    bool s_curve_ = false;        // the ramps are ramp_'s S-curves (a jerk limit on the axis)
    std::int64_t dips_ = 0;       // S-curve: dips at the cruise's start (plan_middle)
    std::int64_t dip_total_ = 0;  // what they take off the plain cruise, LSB
    SCurveRamp ramp_;
    std::int64_t walk_ = 0;  // S-curve: the tangent at the knot next() is at
};

}  // namespace pathstream::device
