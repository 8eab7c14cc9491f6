#include "pathstream/device/motion_limits.hpp"

#include "pathstream/wide_int.hpp"

namespace pathstream::device {
namespace {

constexpr std::uint64_t magnitude64(std::int64_t v) {
    return v < 0 ? static_cast<std::uint64_t>(0) - static_cast<std::uint64_t>(v)
                 : static_cast<std::uint64_t>(v);
}

// |value| * factor <= bound, all exact. |value| < 2^40, factor < 2^40: the product < 2^80.
bool scaled_within(std::int64_t value, std::uint64_t factor, Int128 bound) {
    return multiply_unsigned(magnitude64(value), factor) <= bound;
}

}  // namespace

Status check_axis_limits(const TickCubic& cubic, const SpanTiming& timing, const AxisLimits& limits,
                         std::uint32_t tick_hz) {
    // p(u) = (a u^3 + b u^2 + c u + d) / s with s = D / n^3 and u = k / n. Per second:
    //   velocity     = p'(u) * hz / n    = (3a u^2 + 2b u + c) * hz / (s n)
    //   acceleration = p''(u) * hz^2/n^2 = (6a u + 2b) * hz^2 / (s n^2)
    // Every comparison multiplies out the denominators; nothing is divided.
    const std::uint64_t n = timing.ticks;
    const std::uint64_t scale = timing.denominator / (n * n * n);
    const std::uint64_t hz = tick_hz;

    // Acceleration at u = 0 (2b) and u = 1 (6a + 2b) against a_max * s * n^2 (< 2^70).
    const Int128 accel_bound = multiply_unsigned(limits.max_acceleration * scale, n * n);
    if (!scaled_within(2 * cubic.b, hz * hz, accel_bound) ||
        !scaled_within(6 * cubic.a + 2 * cubic.b, hz * hz, accel_bound)) {
        return Status::kAccelerationLimit;
    }

    // Velocity numerator f(u) = 3a u^2 + 2b u + c against v_max * s * n, at both ends...
    const std::uint64_t velocity_bound_u = limits.max_velocity * scale * n;  // < 2^52
    const Int128 velocity_bound = multiply_unsigned(velocity_bound_u, 1);
    if (!scaled_within(cubic.c, hz, velocity_bound) ||
        !scaled_within(3 * cubic.a + 2 * cubic.b + cubic.c, hz, velocity_bound)) {
        return Status::kVelocityLimit;
    }
    // ...and at the vertex u* = -b / (3a) when it lies inside (0, 1), where
    // f(u*) = (3ac - b^2) / (3a): check |3ac - b^2| * hz <= bound * |3a|.
    const std::int64_t three_a = 3 * cubic.a;
    if (three_a != 0) {
        const std::int64_t minus_b = -cubic.b;
        const bool inside = minus_b != 0 && ((minus_b > 0) == (three_a > 0)) &&
                            magnitude64(minus_b) < magnitude64(three_a);
        if (inside) {
            const Int128 b_squared = multiply_unsigned(magnitude64(cubic.b), magnitude64(cubic.b));
            const Int128 extremum = Int128::from(three_a) * cubic.c - b_squared;
            const Int128 lhs = magnitude(extremum) * static_cast<std::int64_t>(hz);
            const Int128 rhs = multiply_unsigned(velocity_bound_u, magnitude64(three_a));
            if (lhs > rhs) return Status::kVelocityLimit;
        }
    }
    return Status::kOk;
}

Status check_axis_travel(const TickCubic& cubic, const SpanTiming& timing,
                         const AxisLimits& limits) {
    // p(u) = (a u^3 + b u^2 + c u + d) / s: its Bernstein coefficients times 3s are 3d,
    // 3d + c, 3d + 2c + b and 3(a + b + c + d); each against 3s min and 3s max. The
    // coefficients are below 2^40 and s below 2^20, so every product fits 128 bits.
    const std::uint64_t n = timing.ticks;
    const std::int64_t scale = static_cast<std::int64_t>(timing.denominator / (n * n * n));
    const Int128 d3 = Int128::from(cubic.d) * 3;
    const Int128 c = Int128::from(cubic.c);
    const Int128 hull[4] = {
        d3, d3 + c, d3 + c * 2 + Int128::from(cubic.b),
        (Int128::from(cubic.a) + Int128::from(cubic.b) + c + Int128::from(cubic.d)) * 3};
    const Int128 low = Int128::from(limits.min_position) * (3 * scale);
    const Int128 high = Int128::from(limits.max_position) * (3 * scale);
    for (const Int128& h : hull) {
        if (h < low || h > high) return Status::kOutsideTravel;
    }
    return Status::kOk;
}

Status check_join(std::int32_t start_tangent, std::uint32_t ticks,
                  std::int32_t previous_end_tangent, std::uint32_t previous_ticks,
                  const AxisLimits& limits, std::uint32_t tick_hz) {
    // Velocities T0 hz / n and T1' hz / n' (LSB/s); their difference against a_max / hz plus
    // the rounding of each tangent (hz / 2n and hz / 2n'), multiplied by 2 n n' hz.
    const std::int64_t n = ticks, previous = previous_ticks;
    const std::int64_t difference = static_cast<std::int64_t>(start_tangent) * previous -
                                    static_cast<std::int64_t>(previous_end_tangent) * n;  // < 2^47
    const std::uint64_t hz2 = static_cast<std::uint64_t>(tick_hz) * tick_hz;              // < 2^34
    const Int128 lhs = multiply_unsigned(2 * magnitude64(difference), hz2);               // < 2^82
    const Int128 rhs = multiply_unsigned(2 * static_cast<std::uint64_t>(limits.max_acceleration),
                                         static_cast<std::uint64_t>(n * previous)) +  // < 2^65
                       multiply_unsigned(static_cast<std::uint64_t>(n + previous), hz2);
    return lhs <= rhs ? Status::kOk : Status::kVelocityStep;
}

TickAcceleration start_acceleration(const TickCubic& cubic, const SpanTiming& timing) {
    // p''(0) = 2b / s per u^2, over n^2 per tick^2; s n^2 = D / n.
    return TickAcceleration{2 * cubic.b, timing.denominator / timing.ticks};
}

TickAcceleration end_acceleration(const TickCubic& cubic, const SpanTiming& timing) {
    return TickAcceleration{6 * cubic.a + 2 * cubic.b, timing.denominator / timing.ticks};
}

TickAcceleration hermite_end_acceleration(std::int32_t chord, std::int32_t start_tangent,
                                          std::int32_t end_tangent, std::uint32_t n) {
    // |6C| <= 1.5 2^30, |2 T0 + 4 T1| <= 6 2^29: the numerator < 2^33.
    const std::int64_t nn = n;
    return TickAcceleration{
        -6 * std::int64_t{chord} + 2 * std::int64_t{start_tangent} + 4 * std::int64_t{end_tangent},
        static_cast<std::uint64_t>(nn * nn)};
}

Status check_axis_jerk(const TickCubic& cubic, const SpanTiming& timing, const AxisLimits& limits,
                       std::uint32_t tick_hz) {
    if (limits.max_jerk == 0) return Status::kOk;
    // Jerk 6a / D LSB/tick^3, times hz^3 per s^3: |6a| hz^3 (< 2^36 2^50) against J D
    // (< 2^39 2^51).
    const std::uint64_t hz = tick_hz;
    const Int128 lhs = multiply_unsigned(magnitude64(6 * cubic.a), hz * hz * hz);
    const Int128 rhs = multiply_unsigned(static_cast<std::uint64_t>(limits.max_jerk) * kJerkUnitLsb,
                                         timing.denominator);
    return lhs <= rhs ? Status::kOk : Status::kJerkLimit;
}

Status check_acceleration_step(const TickAcceleration& start, const TickAcceleration& previous_end,
                               const AxisLimits& limits, std::uint32_t tick_hz) {
    if (limits.max_jerk == 0) return Status::kOk;
    // |N/Q - N'/Q'| <= J / hz^3, multiplied out: |N Q' - N' Q| hz^3 <= J Q Q'. |N| < 2^36 and
    // Q < 2^35 (docs/exact-math.md): the difference < 2^72, times hz^3 (< 2^50) < 2^122; the
    // bound J Q Q' < 2^39 2^70.
    const Int128 difference =
        Int128::from(start.numerator) * static_cast<std::int64_t>(previous_end.denominator) -
        Int128::from(previous_end.numerator) * static_cast<std::int64_t>(start.denominator);
    const std::int64_t hz = tick_hz;
    const Int128 lhs = magnitude(difference) * (hz * hz * hz);
    const Int128 rhs = multiply_unsigned(static_cast<std::uint64_t>(limits.max_jerk) * kJerkUnitLsb,
                                         start.denominator) *
                       static_cast<std::int64_t>(previous_end.denominator);
    return lhs <= rhs ? Status::kOk : Status::kAccelerationStep;
}

Status check_end_at_rest(const TickAcceleration& end, const AxisLimits& limits,
                         std::uint32_t tick_hz) {
    return check_acceleration_step(TickAcceleration{}, end, limits, tick_hz);
}

}  // namespace pathstream::device
