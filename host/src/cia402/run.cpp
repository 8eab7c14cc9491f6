// The cyclic synchronous position job: enable at the plan's start, one core setpoint per
// cycle (with its velocity and acceleration as feed-forward) and the step check before each
// send, settle at the end point, disable.
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "cycle_setpoints.hpp"
#include "feed_forward.hpp"
#include "pathstream/host/cia402_master.hpp"

namespace pathstream::host {

using namespace cia402;

namespace {

std::uint32_t ticks_per_cycle(const MachineProfile& profile, std::uint32_t cycle_ms) {
    const double c = cycle_ms * profile.tick_hz / 1000.0;
    const double r = std::round(c);
    if (r < 1 || std::fabs(c - r) > 1e-9) {
        throw std::invalid_argument("CiA 402: a " + std::to_string(cycle_ms) +
                                    " ms cycle is not a whole number of " +
                                    std::to_string(profile.tick_hz) + " Hz ticks");
    }
    return static_cast<std::uint32_t>(r);
}

}  // namespace

Cia402Report Cia402Master::run(const Plan& plan, const MachineProfile& profile,
                               const Cia402Progress& progress) {
    const std::size_t axes = profile.axes.size();
    if (plan.spans.empty()) throw std::invalid_argument("CiA 402: the plan has no spans");
    if (plan.spans.front().control.size() != axes)
        throw std::invalid_argument("CiA 402: plan and profile differ in axes");
    if (drives_.size() != axes) {
        throw std::invalid_argument("CiA 402: " + std::to_string(axes) + " axes but " +
                                    std::to_string(drives_.size()) + " drive nodes");
    }
    const std::uint32_t c = ticks_per_cycle(profile, options_.cycle_ms);
    const double cycle_s = options_.cycle_ms / 1000.0;
    // Rounded setpoints differ from the exact motion by < 1/2 LSB each: a step may exceed the
    // exact bound by 1 LSB, a second difference by 2.
    std::vector<std::int64_t> max_step(axes), max_second(axes);
    for (std::size_t a = 0; a < axes; ++a) {
        const double v = profile.axes[a].max_velocity / profile.mm_per_lsb;
        const double acc = profile.axes[a].max_acceleration / profile.mm_per_lsb;
        max_step[a] = static_cast<std::int64_t>(std::floor(v * cycle_s)) + 1;
        max_second[a] = static_cast<std::int64_t>(std::floor(acc * cycle_s * cycle_s)) + 2;
        const double torque = acc * options_.torque_per_acceleration;
        if (options_.feed_forward == Cia402FeedForward::kTorque && torque > 32767) {
            throw std::invalid_argument(
                "CiA 402: axis " + profile.axes[a].name + " would need a torque offset of " +
                std::to_string(std::llround(torque)) +
                " per mille at a_max, beyond 0x60B2's 32767: check the inertia");
        }
    }
    const std::uint64_t t0 = clock_.now();
    report_.total_motion_cycles = (plan.total_ticks + c - 1) / c + 1;
    auto source = make_cycle_setpoints(plan.spans, axes, c);
    // p_(k-2), p_(k-1), the target p_k and, read one cycle ahead for the central acceleration,
    // p_(k+1). Before the start and after the end the axes rest: repeated points.
    std::vector<std::int32_t> target(axes), prev(axes), prev2(axes), ahead(axes);
    source->next(target.data());
    std::uint64_t target_ticks = source->ticks();
    prev = prev2 = target;
    bool have_ahead = source->next(ahead.data());
    std::uint64_t ahead_ticks = source->ticks();
    Offsets offsets{std::vector<std::int32_t>(axes), std::vector<std::int16_t>(axes)};
    // The step check of p_(k+1), before p_k is sent: a refused p_(k+1) is never sent, and
    // the feed-forward sent with p_k takes the axes as stopping there.
    std::string refused;
    auto check_ahead = [&]() {
        refused.clear();
        for (std::size_t a = 0; a < axes && have_ahead; ++a) {
            const std::int64_t step = std::int64_t{ahead[a]} - target[a];
            const std::int64_t second = step - (std::int64_t{target[a]} - prev[a]);
            if (std::llabs(step) <= max_step[a] && std::llabs(second) <= max_second[a]) continue;
            const bool v = std::llabs(step) > max_step[a];
            refused =
                "axis " + profile.axes[a].name + " (node " + std::to_string(drives_[a].node) +
                "): the next target would " +
                (v ? "step " + std::to_string(step) +
                         " LSB in one cycle, more than v_max x cycle = " +
                         std::to_string(max_step[a]) + " LSB"
                   : "change its step by " + std::to_string(second) +
                         " LSB, more than a_max x cycle^2 = " + std::to_string(max_second[a]) +
                         " LSB") +
                "; not sent";
        }
    };
    auto set_offsets = [&]() {
        for (std::size_t a = 0; a < axes; ++a) {
            const bool next = have_ahead && refused.empty();
            const CycleFeedForward f =
                cycle_feed_forward(prev2[a], prev[a], target[a], next ? ahead[a] : target[a],
                                   cycle_s, options_.torque_per_acceleration);
            offsets.velocity[a] = f.velocity;
            offsets.torque[a] = f.torque;
        }
    };

    auto finish = [&](bool completed) {
        report_.completed = completed;
        report_.final_target = target;
        report_.final_position.clear();
        for (const auto& d : drives_) report_.final_position.push_back(d.position);
        report_.path_ticks = target_ticks;
        report_.wall_seconds = static_cast<double>(clock_.now() - t0) / 1e6;
        cycling_ = false;
        return report_;
    };
    auto stop = [&]() {
        quick_stop(target);
        return finish(false);
    };

    // Harmless cycles (shutdown) until every drive has answered a SYNC with its position, before
    // any enables: a drive away from the plan's start would jump there as soon as it takes a
    // target. A drive may answer a cycle late (a busy bus or host: one SYNC's TPDO1 missed 1 run
    // in 10 on a loaded machine), so it has max_missed_feedback cycles, as during motion.
    const std::vector<std::uint16_t> shut_down(axes, kCwShutdown);
    for (unsigned tries = 1;; ++tries) {
        exchange(shut_down, target);
        if (check_health(false) != Cia402Stop::kNone) return stop();
        bool all = true;
        for (const auto& d : drives_) all = all && d.feedback_cycle == cycle_;
        if (all) break;
        if (tries >= options_.max_missed_feedback) {
            for (const auto& d : drives_) {
                if (d.feedback_cycle != cycle_) {
                    stop_with(Cia402Stop::kFeedbackLost,
                              "node " + std::to_string(d.node) + ": no TPDO1 after " +
                                  std::to_string(tries) + " SYNCs before the enable");
                    break;
                }
            }
            return stop();
        }
    }
    for (std::size_t a = 0; a < axes; ++a) {
        const auto& d = drives_[a];
        if (std::llabs(std::int64_t{d.position} - target[a]) > options_.start_tolerance) {
            stop_with(Cia402Stop::kStepLimit,
                      "node " + std::to_string(d.node) + " (axis " + profile.axes[a].name +
                          ") is at " + std::to_string(d.position) + " LSB, the plan starts at " +
                          std::to_string(target[a]) + ": move it there first");
            return stop();
        }
    }
    if (enable(target) != Cia402Stop::kNone) return stop();

    const std::vector<std::uint16_t> enabled(axes, kCwEnableOperation);
    bool more = true;
    while (more) {
        check_ahead();
        set_offsets();
        exchange(enabled, target, &offsets);
        ++report_.motion_cycles;
        for (std::size_t a = 0; a < axes; ++a) {
            const auto& d = drives_[a];
            if (d.feedback_cycle == cycle_) {
                const std::int64_t lag = std::llabs(std::int64_t{target[a]} - d.position);
                if (lag > report_.max_lag) report_.max_lag = static_cast<std::int32_t>(lag);
            }
            if (options_.demand_echo && d.demand_cycle == cycle_ && d.demand != target[a])
                ++report_.demand_mismatches;
        }
        if (check_health(true) != Cia402Stop::kNone) return stop();
        if (progress)
            progress(static_cast<double>(report_.motion_cycles) /
                     static_cast<double>(report_.total_motion_cycles));
        more = have_ahead;
        if (!more) break;
        if (!refused.empty()) {
            stop_with(Cia402Stop::kStepLimit, refused);
            return stop();
        }
        for (std::size_t a = 0; a < axes; ++a) {
            const std::int64_t step = std::llabs(std::int64_t{ahead[a]} - target[a]);
            if (step > report_.max_step) report_.max_step = static_cast<std::int32_t>(step);
        }
        prev2 = prev;
        prev = target;
        target = ahead;
        target_ticks = ahead_ticks;
        have_ahead = source->next(ahead.data());
        ahead_ticks = source->ticks();
    }

    // Hold the end point until every axis has arrived (fresh feedback within the window). The
    // window slides on: the feed-forward winds down with the demand's last velocity change.
    prev2 = prev;
    prev = target;
    const std::uint64_t settle_deadline =
        clock_.now() + std::uint64_t{options_.settle_timeout_ms} * 1000;
    for (;;) {
        bool arrived = true;
        for (std::size_t a = 0; a < axes; ++a) {
            const auto& d = drives_[a];
            arrived = arrived && d.feedback_cycle == cycle_ &&
                      std::llabs(std::int64_t{d.position} - target[a]) <= options_.settle_window;
        }
        if (arrived) break;
        if (clock_.now() >= settle_deadline) {
            stop_with(Cia402Stop::kSettleTimeout, "the axes did not reach the end point within " +
                                                      std::to_string(options_.settle_timeout_ms) +
                                                      " ms");
            return stop();
        }
        set_offsets();
        exchange(enabled, target, &offsets);
        prev2 = prev;
        prev = target;
        if (check_health(true) != Cia402Stop::kNone) return stop();
    }
    if (options_.disable_at_end) {
        for (int i = 0; i < 8; ++i) {
            exchange(shut_down, target);
            bool done = true;
            for (const auto& d : drives_) done = done && d.state() == DriveState::kReadyToSwitchOn;
            if (done) break;
        }
    }
    return finish(true);
}

Cia402Report stream_cia402(const Plan& plan, const MachineProfile& profile,
                           const Cia402Options& options, hal::CanBus& bus, hal::Clock& clock_us,
                           const Cia402Progress& progress) {
    Cia402Master master(bus, clock_us, options);
    master.configure();
    const Cia402Report r = master.run(plan, profile, progress);
    if (!r.completed)
        throw Cia402Error("CiA 402 stopped (" + std::string(cia402_stop_name(r.stop)) +
                          "): " + r.message);
    return r;
}

}  // namespace pathstream::host
