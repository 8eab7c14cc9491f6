#include "pathstream/sim/device.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <memory>
#include <numbers>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "pathstream/hal/linux_clock.hpp"
#include "pathstream/input_shaper.hpp"
#include "pathstream/machine/core_span_conversion.hpp"
#include "pathstream/machine/shaper_design.hpp"
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

/// Checks what a run needs of the profile.
void check_profile(const host::MachineProfile& profile) {
    if (!(profile.tick_hz > 0) || !(profile.mm_per_lsb > 0)) {
        throw std::invalid_argument(
            "the machine profile needs a positive tick rate and mm per LSB");
    }
}

/// The axis count of a plan whose first span is `first`, checked against the device and the
/// profile.
std::size_t plan_axes(const CoreSpan& first, const host::MachineProfile& profile) {
    const std::size_t axes = first.control.size();
    if (axes < 1 || axes > kMaxAxes) {
        throw std::invalid_argument("the plan has " + std::to_string(axes) +
                                    " axes; the device supports 1 to 8");
    }
    if (profile.axes.size() != axes) {
        throw std::invalid_argument("the plan has " + std::to_string(axes) +
                                    " axes but the machine profile " +
                                    std::to_string(profile.axes.size()));
    }
    return axes;
}

/// The lowest natural frequency of the plant (Hz; 0: the ideal plant) and its lag behind a
/// ramp (s): the servo's 2 zeta / omega (a mode, excited through spring and damper, adds none).
struct PlantScales {
    double lowest_hz = 0;
    double lag_seconds = 0;
};

PlantScales plant_scales(const SimOptions& o) {
    PlantScales s;
    if (o.plant != PlantModel::kServo) return s;
    const auto lag = [](double hz, double zeta) { return 2 * zeta / (2 * std::numbers::pi * hz); };
    s.lowest_hz = o.servo.bandwidth_hz;
    s.lag_seconds = lag(o.servo.bandwidth_hz, o.servo.damping);
    for (const auto& axis : o.modes)
        for (const ResonantMode& m : axis) s.lowest_hz = std::min(s.lowest_hz, m.frequency_hz);
    return s;
}

/// Checks the modes against the axes and the plant.
void check_modes(const SimOptions& o, std::size_t axes) {
    if (o.modes.size() > axes) {
        throw std::invalid_argument("resonant modes given for " + std::to_string(o.modes.size()) +
                                    " axes; the plan has " + std::to_string(axes));
    }
    for (const auto& axis : o.modes) {
        if (!axis.empty() && o.plant != PlantModel::kServo)
            throw std::invalid_argument("resonant modes need the servo plant");
    }
}

void check_span_axes(const CoreSpan& span, std::size_t index, std::size_t axes) {
    if (span.control.size() != axes) {
        throw std::invalid_argument("span " + std::to_string(index) + " has " +
                                    std::to_string(span.control.size()) + " axes, the first span " +
                                    std::to_string(axes));
    }
}

}  // namespace

/// The run of one axis count: the stream, the pen, the plants and the spans waiting.
class Simulator::Engine {
public:
    virtual ~Engine() = default;
    virtual void push(const CoreSpan& span) = 0;
    virtual SimulationResult finish() = 0;
    virtual std::uint64_t ticks() const = 0;
};

namespace {

template <unsigned Axes>
class AxesEngine final : public Simulator::Engine {
public:
    using Stream = SetpointStream<Axes, kQueueCapacity>;

    AxesEngine(const CoreSpan& first, const host::MachineProfile& profile,
               const SimOptions& options, hal::Clock* pacing, const Progress& progress,
               std::uint64_t expected_ticks)
        : profile_(profile),
          options_(options),
          pacing_(pacing),
          progress_(progress),
          wall_start_(std::chrono::steady_clock::now()),
          pen_(device_time_),
          residual_(Axes, residual_window_ticks(profile.tick_hz, plant_scales(options).lowest_hz),
                    static_cast<std::uint64_t>(std::ceil(kMinStopSeconds * profile.tick_hz)),
                    options.plant == PlantModel::kServo
                        ? servo_settle_ticks(profile.tick_hz, options.servo.bandwidth_hz,
                                             options.servo.damping)
                        : 0),
          contour_(Axes, contour_back_ticks(profile.tick_hz, plant_scales(options).lag_seconds)),
          interval_(std::max<std::uint32_t>(1, options.producer_interval_ticks)),
          rows_after_end_(1 + options.settle_ticks) {
        check_modes(options, Axes);
        make_shaper(first);
        r_.axes = Axes;
        r_.tick_hz = profile.tick_hz;
        r_.mm_per_lsb = profile.mm_per_lsb;
        r_.plant = options.plant;
        r_.servo = options.servo;
        r_.modes = options.modes;
        r_.paced = pacing != nullptr || options.realtime;
        Lsb start[Axes];
        start_point<Axes>(first, start);
        stream_ = std::make_unique<Stream>(start);  // ~13 KB at 8 axes: heap on the host
        if (options.plant == PlantModel::kServo) {
            for (unsigned a = 0; a < Axes; ++a) {
                servo_.emplace_back(options.servo, profile.tick_seconds(),
                                    start[a] * profile.mm_per_lsb);
                const bool rings = a < options.modes.size() && !options.modes[a].empty();
                resonant_.push_back(rings
                                        ? std::make_unique<ResonantAxis>(
                                              options.servo, options.modes[a],
                                              profile.tick_seconds(), start[a] * profile.mm_per_lsb)
                                        : nullptr);
            }
        }
        expected_rows_ = expected_ticks + rows_after_end_;
        if (options.record_ticks && expected_ticks > 0) {
            r_.setpoints.reserve(expected_rows_ * Axes);
            r_.positions.reserve(expected_rows_ * Axes);
            r_.pen.reserve(expected_rows_);
        }
        progress_stride_ =
            expected_ticks > 0 ? std::max<std::uint64_t>(1, expected_rows_ / 100) : 0;
        r_.following.assign(Axes, FollowingError{});
    }

    void push(const CoreSpan& span) override {
        r_.plan_ticks += span.ticks;
        pending_.push_back(span);
        advance(false);
    }

    SimulationResult finish() override {
        advance(true);
        for (unsigned a = 0; a < Axes; ++a) {
            r_.following[a].rms_mm = std::sqrt(sum_sq_[a] / static_cast<double>(r_.ticks));
        }
        r_.residual = residual_.finish();
        r_.contour = contour_.finish();
        if (command_contour_) r_.shaped_command = command_contour_->finish();
        r_.stream.ticks_executed = stream_->ticks_executed();
        r_.stream.spans_completed = stream_->spans_completed();
        r_.stream.last_completed_tag = stream_->last_completed_tag();
        r_.pen_switch_ticks = pen_.switch_ticks();
        r_.simulated_seconds = static_cast<double>(r_.ticks) / profile_.tick_hz;
        r_.wall_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start_).count();
        if (progress_) progress_(1.0);
        return std::move(r_);
    }

    std::uint64_t ticks() const override { return r_.ticks; }

private:
    using Shaper = InputShaper<Axes, host::kDeviceShaperHistoryTicks>;

    /// The device's input shaper when an axis has taps; the run gets its longest delay more.
    void make_shaper(const CoreSpan& first) {
        if (options_.shaper.size() > Axes) {
            throw std::invalid_argument("input shapers given for " +
                                        std::to_string(options_.shaper.size()) +
                                        " axes, the run has " + std::to_string(Axes));
        }
        bool any = false;
        for (const auto& taps : options_.shaper) any = any || !taps.empty();
        if (!any) return;
        Lsb start[Axes];
        start_point<Axes>(first, start);
        shaper_ = std::make_unique<Shaper>(start);
        for (unsigned a = 0; a < options_.shaper.size(); ++a) {
            const auto& taps = options_.shaper[a];
            if (shaper_->configure(a, taps.data(), static_cast<std::uint32_t>(taps.size())) !=
                Status::kOk) {
                throw std::invalid_argument("axis " + std::to_string(a) +
                                            ": the device refuses these input shaper taps");
            }
        }
        rows_after_end_ += shaper_->longest_delay();
        command_contour_.emplace(
            Axes, contour_back_ticks(profile_.tick_hz, 0) + shaper_->longest_delay());
    }

    /// The producer task: pushes waiting spans while the queue takes them.
    void produce() {
        std::uint32_t pushed = 0;
        while (!pending_.empty() &&
               (options_.max_pushes_per_run == 0 || pushed < options_.max_pushes_per_run)) {
            const std::size_t index = next_;
            const Status s = stream_->push(
                host::to_core_span<Axes>(pending_.front(), static_cast<std::uint32_t>(index + 1)));
            if (s == Status::kQueueFull) {
                ++r_.stream.queue_full;
                break;
            }
            if (s != Status::kOk) throw std::runtime_error(span_error(index, s));
            ticks_pushed_ += pending_.front().ticks;
            pending_.pop_front();
            ++next_;
            ++pushed;
            ++r_.spans_pushed;
        }
        r_.stream.max_queued = std::max(r_.stream.max_queued, stream_->queued_spans());
    }

    /// Spans the producer's next run takes or tries with a whole plan waiting: up to
    /// max_pushes_per_run when the queue has room for them, else as many as it has room for
    /// and one more (answered kQueueFull).
    std::size_t wanted() const {
        const std::uint32_t room = kQueueCapacity - stream_->queued_spans();
        const std::uint32_t most = options_.max_pushes_per_run;
        return most > 0 && room >= most ? most : std::size_t{room} + 1;
    }

    /// Runs ticks until the run ends or, unless `final`, until the producer is due with fewer
    /// spans waiting than it would take or try with the whole plan there, or every span given
    /// is done: what happens then depends on the spans still to come, so they are needed first.
    void advance(bool final) {
        while (!done_) {
            const std::uint64_t k = k_;
            if (k % interval_ == 0 && !produced_) {
                if (!final && pending_.size() < wanted()) return;
                produce();  // the producer task, between two tick interrupts
                produced_ = true;
            }
            // Every span given done: whether the plan ended (no underrun, the end point next)
            // depends on the spans still to come.
            const bool all_done = pending_.empty() && stream_->spans_completed() == next_;
            if (!final && all_done) return;
            const bool finished = final && all_done;
            if (pacing_ == nullptr && options_.realtime) {
                // Real time: the Linux clock's tick 0 is the first tick's, not the first span's
                // arrival (the device may wait for more spans first).
                own_clock_ = std::make_unique<hal::LinuxClock>(profile_.tick_hz);
                pacing_ = own_clock_.get();
            }
            if (pacing_ != nullptr) {
                pacing_->wait_until(k);
                if (pacing_->now() > k) ++r_.late_ticks;
            }
            device_time_.wait_until(k);

            // --- the tick interrupt ---
            const TickState state = stream_->tick(out_);
            pen_.set((stream_->outputs() & kOutputPenDown) != 0);
            // ---

            if (state == TickState::kIdle) {
                ++r_.stream.idle_ticks;
                if (!finished) ++r_.underruns;
            }
            const bool pen_down = pen_.state();
            if (options_.record_ticks) r_.pen.push_back(pen_down ? 1 : 0);
            double positions[Axes], carriage[Axes];
            // The planned setpoints (the contour's reference) and the command into the plant:
            // the input shaper's output when there is one.
            double reference[Axes], command[Axes];
            if (shaper_) shaper_->shape(out_, shaped_);
            const Lsb* const device_out = shaper_ ? shaped_ : out_;
            for (unsigned a = 0; a < Axes; ++a) {
                reference[a] = out_[a] * profile_.mm_per_lsb;
                const double setpoint_mm = device_out[a] * profile_.mm_per_lsb;
                command[a] = setpoint_mm;
                double position = setpoint_mm;
                carriage[a] = setpoint_mm;
                if (!servo_.empty() && resonant_[a]) {
                    position = resonant_[a]->tool_position();  // at the tick's instant
                    carriage[a] = resonant_[a]->motor_position();
                    resonant_[a]->step(setpoint_mm);
                } else if (!servo_.empty()) {
                    position = servo_[a].position();  // at this tick's instant, before its hold
                    carriage[a] = position;
                    servo_[a].step(setpoint_mm);
                }
                positions[a] = position;
                if (options_.record_ticks) {
                    r_.setpoints.push_back(device_out[a]);
                    r_.positions.push_back(position);
                }
                const double e = std::fabs(setpoint_mm - position);
                sum_sq_[a] += e * e;
                if (e > r_.following[a].max_mm) {
                    r_.following[a].max_mm = e;
                    r_.following[a].max_tick = k;
                }
            }
            residual_.add(command, positions, carriage);
            contour_.add(reference, positions);
            if (command_contour_) command_contour_->add(reference, command);
            r_.ticks = k + 1;
            if (options_.tick_observer) {
                options_.tick_observer({k, stream_->ticks_executed(), stream_->last_completed_tag(),
                                        stream_->queued_spans(), ticks_pushed_, device_out,
                                        positions, pen_down});
            }
            if (progress_ && progress_stride_ > 0 && r_.ticks % progress_stride_ == 0) {
                progress_(std::min(
                    1.0, static_cast<double>(r_.ticks) / static_cast<double>(expected_rows_)));
            }
            ++k_;
            produced_ = false;
            if (finished && --rows_after_end_ == 0) done_ = true;
        }
    }

    const host::MachineProfile& profile_;
    const SimOptions& options_;
    hal::Clock* pacing_;
    std::unique_ptr<hal::LinuxClock> own_clock_;  // real time without an injected clock
    const Progress& progress_;
    std::chrono::steady_clock::time_point wall_start_;
    SimulationResult r_;
    std::unique_ptr<Stream> stream_;
    VirtualClock device_time_;  // the device's tick counter
    SimulatedOutput pen_;       // the pen lift, stamped in device ticks
    std::vector<ServoAxis> servo_;
    std::unique_ptr<Shaper> shaper_;  // null: no axis shaped
    Lsb shaped_[Axes] = {};
    std::vector<std::unique_ptr<ResonantAxis>> resonant_;  // per axis with servo_; null: none
    ResidualVibrationMeter residual_;
    ContourErrorMeter contour_;
    std::optional<ContourErrorMeter> command_contour_;  // with a shaper
    std::deque<CoreSpan> pending_;                      // spans given, not yet taken by the device
    std::size_t next_ = 0;                              // spans the device took
    std::uint64_t ticks_pushed_ = 0;
    std::uint32_t interval_;
    std::uint64_t rows_after_end_;  // end point + settling
    std::uint64_t expected_rows_ = 0;
    std::uint64_t progress_stride_ = 0;
    std::uint64_t k_ = 0;    // the next tick
    bool produced_ = false;  // the producer ran before tick k_
    bool done_ = false;
    double sum_sq_[Axes] = {};
    Lsb out_[Axes] = {};
};

SimulationResult dispatch(const std::vector<CoreSpan>& spans, const host::MachineProfile& profile,
                          const SimOptions& options, hal::Clock* pacing, const Progress& progress) {
    if (spans.empty()) throw std::invalid_argument("no spans: nothing to simulate");
    const std::size_t axes = plan_axes(spans.front(), profile);
    for (std::size_t i = 0; i < spans.size(); ++i) check_span_axes(spans[i], i, axes);
    check_profile(profile);
    std::uint64_t ticks = 0;
    for (const CoreSpan& s : spans) ticks += s.ticks;
    Simulator simulator(profile, options, pacing, progress, ticks);
    for (const CoreSpan& s : spans) simulator.push(s);
    return simulator.finish();
}

}  // namespace

Simulator::Simulator(const host::MachineProfile& profile, const SimOptions& options,
                     hal::Clock* pacing, Progress progress, std::uint64_t expected_ticks)
    : profile_(profile),
      options_(options),
      pacing_(pacing),
      progress_(std::move(progress)),
      expected_ticks_(expected_ticks) {
    check_profile(profile);
}

Simulator::~Simulator() = default;

void Simulator::push(const CoreSpan& span) {
    if (!engine_) {
        axes_ = plan_axes(span, profile_);
        engine_ = host::with_axes(axes_, [&](auto n) -> std::unique_ptr<Engine> {
            return std::make_unique<AxesEngine<decltype(n)::value>>(
                span, profile_, options_, pacing_, progress_, expected_ticks_);
        });
    }
    check_span_axes(span, spans_, axes_);
    ++spans_;
    engine_->push(span);
}

SimulationResult Simulator::finish() {
    if (!engine_) throw std::invalid_argument("no spans: nothing to simulate");
    return engine_->finish();
}

std::uint64_t Simulator::ticks() const {
    return engine_ ? engine_->ticks() : 0;
}

SimulationResult simulate(const std::vector<CoreSpan>& spans, const host::MachineProfile& profile,
                          const SimOptions& options, const Progress& progress) {
    return dispatch(spans, profile, options, nullptr, progress);
}

SimulationResult simulate_paced(const std::vector<CoreSpan>& spans,
                                const host::MachineProfile& profile, const SimOptions& options,
                                hal::Clock& pacing, const Progress& progress) {
    return dispatch(spans, profile, options, &pacing, progress);
}

}  // namespace pathstream::sim
