// Test support for the device: a planned move as wire spans, batches of them, and a run loop
// that records every tick.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"

namespace pathstream::test {

/// Limits used by the device tests: 1 kHz, 200,000 LSB/s and 2,000,000 LSB/s^2 per axis
/// (200 mm/s and 2 m/s^2 at 1 um per LSB).
template <unsigned Axes>
device::MotionLimits<Axes> test_limits() {
    device::MotionLimits<Axes> l;
    l.tick_hz = 1000;
    for (unsigned a = 0; a < Axes; ++a) l.axis[a] = {200000, 2000000};
    return l;
}

/// A straight move of `distance` LSB on every axis (axis a moves distance * (a + 1) / Axes)
/// with a trapezoidal speed profile, as Hermite wire spans of `ticks` ticks each from rest to
/// rest, starting at `start`. Speed and acceleration stay within 75 % of test_limits.
template <unsigned Axes>
std::vector<device::WireSpan> trapezoid_move(const Lsb (&start)[Axes], double distance,
                                             std::uint32_t ticks) {
    // Phases last whole spans, so each span is one quadratic piece that its Hermite form
    // reproduces exactly (a phase change inside a span would bend it past the limits).
    const double span = ticks;
    const double ramp = std::ceil(100.0 / span) * span;  // 150 LSB/tick reached at 1.5 LSB/tick^2
    const double cruise =
        std::max(0.0, std::ceil((std::fabs(distance) / 150.0 - ramp) / span) * span);
    const double peak = distance / (ramp + cruise);
    const double acc = peak / ramp;
    const double total = 2 * ramp + cruise;
    auto along = [&](double t, double& s, double& speed) {
        if (t <= ramp) {
            s = 0.5 * acc * t * t;
            speed = acc * t;
        } else if (t <= ramp + cruise) {
            s = 0.5 * acc * ramp * ramp + peak * (t - ramp);
            speed = peak;
        } else if (t < total) {
            const double r = total - t;
            s = distance - 0.5 * acc * r * r;
            speed = acc * r;
        } else {
            s = distance;
            speed = 0;
        }
    };
    const std::uint32_t spans = static_cast<std::uint32_t>(std::ceil(total / ticks));
    std::vector<device::WireSpan> out;
    for (std::uint32_t i = 1; i <= spans; ++i) {
        double s = 0, speed = 0;
        along(static_cast<double>(i) * ticks, s, speed);
        device::WireSpan w;
        w.ticks = ticks;
        w.flags = i == 1 ? 0 : device::kWireContinueTangent;
        w.outputs = kOutputPenDown;
        for (unsigned a = 0; a < Axes; ++a) {
            const double share = static_cast<double>(a + 1) / Axes;
            w.end[a] = start[a] + static_cast<std::int32_t>(std::llround(s * share));
            w.end_tangent[a] = static_cast<std::int32_t>(std::llround(speed * share * ticks));
            w.start_tangent[a] = 0;
        }
        out.push_back(w);
    }
    return out;
}

/// Wire bytes of spans [first, first + count).
template <unsigned Axes>
std::vector<std::uint8_t> batch_bytes(const std::vector<device::WireSpan>& spans, std::size_t first,
                                      std::size_t count) {
    std::vector<std::uint8_t> bytes;
    for (std::size_t i = first; i < first + count; ++i) {
        std::uint8_t buffer[4 + 12 * kMaxAxes];
        const std::size_t n = device::encode_wire_span(spans[i], Axes, buffer, sizeof buffer);
        bytes.insert(bytes.end(), buffer, buffer + n);
    }
    return bytes;
}

}  // namespace pathstream::test
