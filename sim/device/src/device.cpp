#include "pathstream/sim/device.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "pathstream/hal/linux_clock.hpp"
#include "pathstream/machine/core_span_conversion.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/sim/simulated_output.hpp"
#include "pathstream/sim/virtual_clock.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"

namespace pathstream::sim {
namespace {

using host::CoreSpan;

std::string span_error(std::size_t index, Status s) {
    std::ostringstream m;
    m << "span " << index << " (tag " << index + 1
      << "): the device refused it: " << status_name(s);
    return m.str();
}

/// Where the first span starts, by the core's own evaluation (independent of the CoreSpan's
/// cached cubic, which a hand-made plan may lack).
template <unsigned Axes>
void start_point(const CoreSpan& first, Lsb (&start)[Axes]) {
    const Span<Axes> s = host::to_core_span<Axes>(first, 1);
    ValidatedSpan<Axes> v;
    if (const Status st = validate_span(s, v); st != Status::kOk) {
        throw std::runtime_error(span_error(0, st));
    }
    for (unsigned a = 0; a < Axes; ++a) {
        if (const Status st = evaluate_at(v.cubic[a], v.timing, 0, start[a]); st != Status::kOk) {
            throw std::runtime_error(span_error(0, st));
        }
    }
}

template <unsigned Axes>
SimulationResult run(const std::vector<CoreSpan>& spans, const host::MachineProfile& profile,
                     const SimOptions& options, hal::Clock* pacing, const Progress& progress) {
    using Stream = SetpointStream<Axes, kQueueCapacity>;
    const auto wall_start = std::chrono::steady_clock::now();
    const std::size_t span_count = spans.size();

    SimulationResult r;
    r.axes = Axes;
    r.tick_hz = profile.tick_hz;
    r.mm_per_lsb = profile.mm_per_lsb;
    r.plant = options.plant;
    r.servo = options.servo;
    r.paced = pacing != nullptr;
    for (const CoreSpan& s : spans) r.plan_ticks += s.ticks;

    Lsb start[Axes];
    start_point<Axes>(spans.front(), start);
    auto stream = std::make_unique<Stream>(start);  // ~13 KB at 8 axes: heap on the host

    VirtualClock device_time;          // the device's tick counter
    SimulatedOutput pen(device_time);  // the pen lift, stamped in device ticks

    std::vector<ServoAxis> servo;
    if (options.plant == PlantModel::kServo) {
        for (unsigned a = 0; a < Axes; ++a) {
            servo.emplace_back(options.servo, profile.tick_seconds(),
                               start[a] * profile.mm_per_lsb);
        }
    }

    const std::uint64_t expected_rows = r.plan_ticks + 1 + options.settle_ticks;
    r.setpoints.reserve(expected_rows * Axes);
    r.positions.reserve(expected_rows * Axes);
    r.pen.reserve(expected_rows);
    std::vector<double> sum_sq(Axes, 0.0);
    r.following.assign(Axes, FollowingError{});

    std::size_t next = 0;  // next span to push
    const auto produce = [&] {
        std::uint32_t pushed = 0;
        while (next < span_count &&
               (options.max_pushes_per_run == 0 || pushed < options.max_pushes_per_run)) {
            const Status s = stream->push(
                host::to_core_span<Axes>(spans[next], static_cast<std::uint32_t>(next + 1)));
            if (s == Status::kQueueFull) {
                ++r.stream.queue_full;
                break;
            }
            if (s != Status::kOk) throw std::runtime_error(span_error(next, s));
            ++next;
            ++pushed;
            ++r.spans_pushed;
        }
        r.stream.max_queued = std::max(r.stream.max_queued, stream->queued_spans());
    };

    const std::uint32_t interval = std::max<std::uint32_t>(1, options.producer_interval_ticks);
    const std::uint64_t progress_stride = std::max<std::uint64_t>(1, expected_rows / 100);
    std::uint64_t rows_after_end = 1 + options.settle_ticks;  // end point + settling
    Lsb out[Axes];
    for (std::uint64_t k = 0;; ++k) {
        if (k % interval == 0) produce();  // the producer task, between two tick interrupts
        if (pacing != nullptr) {
            pacing->wait_until(k);
            if (pacing->now() > k) ++r.late_ticks;
        }
        device_time.wait_until(k);
        const bool finished = stream->spans_completed() == span_count;

        // --- the tick interrupt ---
        const TickState state = stream->tick(out);
        pen.set((stream->outputs() & kOutputPenDown) != 0);
        // ---

        if (state == TickState::kIdle) {
            ++r.stream.idle_ticks;
            if (!finished) ++r.underruns;
        }
        r.pen.push_back(pen.state() ? 1 : 0);
        for (unsigned a = 0; a < Axes; ++a) {
            const double setpoint_mm = out[a] * profile.mm_per_lsb;
            double position = setpoint_mm;
            if (!servo.empty()) {
                position = servo[a].position();  // at this tick's instant, before its hold
                servo[a].step(setpoint_mm);
            }
            r.setpoints.push_back(out[a]);
            r.positions.push_back(position);
            const double e = std::fabs(setpoint_mm - position);
            sum_sq[a] += e * e;
            if (e > r.following[a].max_mm) {
                r.following[a].max_mm = e;
                r.following[a].max_tick = k;
            }
        }
        r.ticks = k + 1;
        if (options.tick_observer) {
            options.tick_observer({k, stream->ticks_executed(), stream->last_completed_tag(),
                                   stream->queued_spans(), out});
        }
        if (progress && r.ticks % progress_stride == 0) {
            progress(
                std::min(1.0, static_cast<double>(r.ticks) / static_cast<double>(expected_rows)));
        }
        if (finished && --rows_after_end == 0) break;
    }

    for (unsigned a = 0; a < Axes; ++a) {
        r.following[a].rms_mm = std::sqrt(sum_sq[a] / static_cast<double>(r.ticks));
    }
    r.stream.ticks_executed = stream->ticks_executed();
    r.stream.spans_completed = stream->spans_completed();
    r.stream.last_completed_tag = stream->last_completed_tag();
    r.pen_switch_ticks = pen.switch_ticks();
    r.simulated_seconds = static_cast<double>(r.ticks) / profile.tick_hz;
    r.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
    if (progress) progress(1.0);
    return r;
}

SimulationResult dispatch(const std::vector<CoreSpan>& spans, const host::MachineProfile& profile,
                          const SimOptions& options, hal::Clock* pacing, const Progress& progress) {
    if (spans.empty()) throw std::invalid_argument("no spans: nothing to simulate");
    const std::size_t axes = spans.front().control.size();
    if (axes < 1 || axes > kMaxAxes) {
        throw std::invalid_argument("the plan has " + std::to_string(axes) +
                                    " axes; the device supports 1 to 8");
    }
    for (std::size_t i = 0; i < spans.size(); ++i) {
        if (spans[i].control.size() != axes) {
            throw std::invalid_argument("span " + std::to_string(i) + " has " +
                                        std::to_string(spans[i].control.size()) +
                                        " axes, the first span " + std::to_string(axes));
        }
    }
    if (profile.axes.size() != axes) {
        throw std::invalid_argument("the plan has " + std::to_string(axes) +
                                    " axes but the machine profile " +
                                    std::to_string(profile.axes.size()));
    }
    if (!(profile.tick_hz > 0) || !(profile.mm_per_lsb > 0)) {
        throw std::invalid_argument(
            "the machine profile needs a positive tick rate and mm per LSB");
    }
    return host::with_axes(axes, [&](auto n) {
        return run<decltype(n)::value>(spans, profile, options, pacing, progress);
    });
}

}  // namespace

SimulationResult simulate(const std::vector<CoreSpan>& spans, const host::MachineProfile& profile,
                          const SimOptions& options, const Progress& progress) {
    if (!options.realtime) return dispatch(spans, profile, options, nullptr, progress);
    hal::LinuxClock clock(profile.tick_hz);
    return dispatch(spans, profile, options, &clock, progress);
}

SimulationResult simulate_paced(const std::vector<CoreSpan>& spans,
                                const host::MachineProfile& profile, const SimOptions& options,
                                hal::Clock& pacing, const Progress& progress) {
    return dispatch(spans, profile, options, &pacing, progress);
}

}  // namespace pathstream::sim
