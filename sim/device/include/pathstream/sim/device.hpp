// The simulated device: the firmware core's SetpointStream fed with a plan's spans and ticked
// by a clock, driving a pen output and a plant per axis. Fed span by span (Simulator) or with a
// whole plan (simulate); every tick is recorded unless SimOptions::record_ticks is off.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "pathstream/hal/clock.hpp"
#include "pathstream/machine/core_span.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/shaper_taps.hpp"
#include "pathstream/sim/contour_error.hpp"
#include "pathstream/sim/plant.hpp"
#include "pathstream/sim/residual_vibration.hpp"
#include "pathstream/sim/resonant_axis.hpp"
#include "pathstream/units.hpp"

namespace pathstream::sim {

/// Span queue depth of the simulated device (SetpointStream<Axes, kQueueCapacity>).
inline constexpr std::uint32_t kQueueCapacity = 32;

/// One tick as the simulated device ran it: what live observers (sim --events) look at.
struct TickProbe {
    std::uint64_t tick = 0;                ///< the tick's number (0: the first)
    std::uint64_t ticks_executed = 0;      ///< path ticks so far (SetpointStream::ticks_executed)
    std::uint32_t last_completed_tag = 0;  ///< tag (span index + 1) of the last span done, 0: none
    std::uint32_t queued_spans = 0;        ///< spans queued, the one in progress included
    std::uint64_t ticks_pushed = 0;        ///< ticks of every span the device accepted so far
    const Lsb* setpoints = nullptr;        ///< the tick's setpoints, one per axis
    const double* positions = nullptr;     ///< mm per axis: the plant's (tool's) position
    bool pen_down = false;                 ///< the pen output after the tick
};

/// How to run.
struct SimOptions {
    PlantModel plant = PlantModel::kIdeal;
    ServoParameters servo;  ///< used when plant == kServo
    /// Resonant modes per axis, in axis order (docs/simulator.md): an axis with modes is a
    /// ResonantAxis (the servo driving them; its position is the tool's). Shorter than the
    /// axes: the rest have none. Only with kServo (std::invalid_argument with kIdeal).
    std::vector<std::vector<ResonantMode>> modes;
    /// The device's input shaper per axis, in axis order (docs/input-shaping.md): taps as
    /// check_shaper_taps takes them with a history of host::kDeviceShaperHistoryTicks, empty
    /// for an unshaped axis; shorter than the axes: the rest are unshaped. The shaped
    /// setpoints drive the plant and are what the run records; the planned ones stay the
    /// contour error's reference. The run lasts the longest delay longer, so the shaped
    /// output reaches the end point. std::invalid_argument for taps the device refuses.
    std::vector<std::vector<ShaperTap>> shaper;
    bool realtime = false;           ///< pace ticks with the Linux monotonic clock
    std::uint64_t settle_ticks = 0;  ///< idle ticks run after the end point (plant settling)
    /// The producer task runs before every `producer_interval_ticks`-th tick and pushes up to
    /// `max_pushes_per_run` spans (0: until the queue is full). Defaults keep the queue full;
    /// larger intervals or small batches model a slow link (and can starve the queue).
    std::uint32_t producer_interval_ticks = 1;
    std::uint32_t max_pushes_per_run = 0;
    /// Called after every tick when set: keep it cheap, it runs at the tick rate.
    std::function<void(const TickProbe&)> tick_observer;
    /// Keep every tick in SimulationResult::setpoints, positions and pen. Off: those stay
    /// empty and memory does not grow with the run (a tick_observer sees every tick instead).
    bool record_ticks = true;
};

/// Following error of one axis, |setpoint - plant position| over every tick (the tool's
/// position on an axis with resonant modes).
struct FollowingError {
    double max_mm = 0;
    double rms_mm = 0;
    std::uint64_t max_tick = 0;  ///< tick of the maximum
};

/// The stream's own counters at the end of the run, plus what the producer saw.
struct StreamCounters {
    std::uint64_t ticks_executed = 0;      ///< SetpointStream::ticks_executed()
    std::uint32_t spans_completed = 0;     ///< SetpointStream::spans_completed()
    std::uint32_t last_completed_tag = 0;  ///< tag = span index + 1
    std::uint64_t idle_ticks = 0;          ///< ticks that returned TickState::kIdle
    std::uint64_t queue_full = 0;          ///< pushes answered kQueueFull (retried later)
    std::uint32_t max_queued = 0;          ///< deepest the queue got (<= kQueueCapacity)
};

/// Everything one run produced. Per-tick records (only with SimOptions::record_ticks) are
/// row-major, row k = tick k: ticks 0 to plan ticks - 1 come from spans, then one tick holding
/// the end point, then settle_ticks (more rows if the queue ran dry: see underruns).
struct SimulationResult {
    std::size_t axes = 0;
    double tick_hz = 0;
    double mm_per_lsb = 0;
    PlantModel plant = PlantModel::kIdeal;
    ServoParameters servo;
    std::vector<std::vector<ResonantMode>> modes;  ///< SimOptions::modes

    std::uint64_t ticks = 0;         ///< ticks run = rows recorded
    std::uint64_t plan_ticks = 0;    ///< sum of the plan's span ticks
    std::uint64_t spans_pushed = 0;  ///< accepted by push()
    StreamCounters stream;
    std::vector<std::uint64_t> pen_switch_ticks;  ///< ticks at which the pen output changed
    std::uint64_t underruns = 0;   ///< idle ticks before the last span finished (0 expected)
    bool paced = false;            ///< ticks were paced by a clock (realtime, or injected)
    std::uint64_t late_ticks = 0;  ///< paced runs: ticks that began a whole tick late
    double simulated_seconds = 0;  ///< ticks / tick_hz
    double wall_seconds = 0;       ///< host time the run took

    std::vector<Lsb> setpoints;             ///< LSB, from the core, [tick * axes + axis]
    std::vector<double> positions;          ///< mm, the plant's position at the tick's instant
    std::vector<std::uint8_t> pen;          ///< pen output after the tick (1: down)
    std::vector<FollowingError> following;  ///< per axis
    /// After the command into the plant came to rest, over every tick (docs/simulator.md).
    ResidualVibration residual;
    /// The tool's distance from the planned setpoints' polyline, over every tick.
    ContourError contour;
    /// With an input shaper: the shaped command's own distance from the planned setpoints'
    /// polyline (the contour error of an ideal plant, from the exact integer setpoints): what
    /// the shaper cuts off corners. Zero without one.
    ContourError shaped_command;

    Lsb setpoint(std::uint64_t tick, std::size_t axis) const {
        return setpoints[tick * axes + axis];
    }
    double position(std::uint64_t tick, std::size_t axis) const {
        return positions[tick * axes + axis];
    }
};

/// Called now and then (about every 1 % of the ticks, and with 1.0 at the end) with the
/// fraction done.
using Progress = std::function<void(double fraction)>;

/// The simulated device fed a plan span by span, as a planner makes them: memory stays bounded
/// whatever the plan's length (with SimOptions::record_ticks off). The run is the one
/// simulate() makes of the same spans, tick for tick: push() runs the device only as far as
/// it can without knowing the spans still to come (the producer runs only with as many spans
/// waiting as it would push, and one more where the queue would answer kQueueFull), finish()
/// runs it to the end.
class Simulator {
public:
    /// `pacing`: as simulate_paced (null: options.realtime decides, with the Linux clock's tick
    /// 0 at the first tick). `expected_ticks`: the
    /// plan's ticks when known (0: not), for `progress` (called as simulate's; else only with
    /// 1.0 at the end) and to reserve the per-tick record. Throws std::invalid_argument for a
    /// profile without a positive tick rate and mm per LSB.
    Simulator(const host::MachineProfile& profile, const SimOptions& options,
              hal::Clock* pacing = nullptr, Progress progress = {},
              std::uint64_t expected_ticks = 0);
    ~Simulator();
    Simulator(const Simulator&) = delete;
    Simulator& operator=(const Simulator&) = delete;

    /// The plan's next span (its tag: spans pushed before it + 1); runs the device's ticks
    /// that do not depend on the spans after it. Keeps at most kQueueCapacity + 1 spans
    /// waiting. Throws as simulate does, for this span (std::invalid_argument for its axis
    /// count, std::runtime_error when the device refuses it).
    void push(const host::CoreSpan& span);
    /// The plan ended: runs the device to the end point and settle_ticks, and returns the
    /// run (std::invalid_argument when no span was pushed). Call once.
    SimulationResult finish();
    /// Ticks run so far.
    std::uint64_t ticks() const;

    class Engine;

private:
    const host::MachineProfile& profile_;
    SimOptions options_;
    hal::Clock* pacing_;
    Progress progress_;
    std::uint64_t expected_ticks_;
    std::unique_ptr<Engine> engine_;
    std::size_t axes_ = 0;
    std::size_t spans_ = 0;
};

/// Runs `spans` (a plan's) on the simulated device: a SetpointStream<axes, kQueueCapacity> (axes =
/// the spans' axis count, 1..8) starting at the first span's start point, a producer pushing the
/// spans (Span::tag = index + 1, outputs = kOutputPenDown on pen-down spans) whenever
/// there is room, one tick() per clock tick, the pen output set from outputs() after each
/// tick, and the plant stepped with the tick's setpoint. Virtual time (as fast as possible)
/// unless options.realtime (hal::LinuxClock at profile.tick_hz).
/// Throws std::invalid_argument for an empty plan, spans whose axis count differs from the
/// profile's, bad servo parameters or resonant modes (more mode lists than axes, modes
/// without the servo plant, a mode check_resonant_mode refuses); std::runtime_error ("span I (tag
/// T): the device refused it: <status name>") when push() answers anything but kOk or kQueueFull.
SimulationResult simulate(const std::vector<host::CoreSpan>& spans,
                          const host::MachineProfile& profile, const SimOptions& options,
                          const Progress& progress = {});

/// The same run paced by `pacing` (options.realtime is ignored): before tick k the device
/// calls pacing.wait_until(k), and counts the tick late when pacing.now() > k afterwards.
/// Tests inject a clock here to check the pacing without measuring wall time.
SimulationResult simulate_paced(const std::vector<host::CoreSpan>& spans,
                                const host::MachineProfile& profile, const SimOptions& options,
                                hal::Clock& pacing, const Progress& progress = {});

}  // namespace pathstream::sim
