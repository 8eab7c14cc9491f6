// Test support for the CiA 402 tests: a single-threaded in-process CAN bus on a virtual
// microsecond clock. The master's endpoint, when it would wait, runs the simulated drives
// (service) and advances the clock in small steps, so a whole job runs deterministically and
// as fast as it computes; seeded frame loss per receiver.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "pathstream/hal/can_bus.hpp"
#include "pathstream/hal/clock.hpp"
#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/sim/cia402_drive.hpp"

namespace cia402_test {

using namespace pathstream;

/// Microseconds; advanced only by the bus (or the test).
class MicrosecondClock final : public hal::Clock {
public:
    std::uint64_t now() const override { return now_; }
    void wait_until(std::uint64_t t) override {
        if (t > now_) now_ = t;
    }
    void advance(std::uint64_t us) { now_ += us; }

private:
    std::uint64_t now_ = 0;
};

class Hub;

/// One node's view of the hub.
class Endpoint final : public hal::CanBus {
public:
    Endpoint(Hub& hub, bool serviced) : hub_(hub), serviced_(serviced) {}
    hal::CanSendResult send(const hal::CanFrame& frame) override;
    bool receive(hal::CanFrame& out, std::uint32_t timeout_us) override;
    hal::CanBusState state() const override { return state_; }

    std::deque<hal::CanFrame> rx;
    hal::CanBusState state_ = hal::CanBusState::kErrorActive;

private:
    Hub& hub_;
    bool serviced_;
};

/// The bus: every frame goes to every other endpoint (no echo), each copy lost with
/// probability `loss` (decided by a seeded generator, in send order); `drop` lets a test
/// lose chosen frames. `service` runs the other nodes; `step_us` is the time grain.
class Hub {
public:
    explicit Hub(double loss_fraction = 0, std::uint64_t seed = 1)
        : loss(loss_fraction), random_(seed) {}

    Endpoint& add(bool serviced) {
        endpoints_.push_back(std::make_unique<Endpoint>(*this, serviced));
        return *endpoints_.back();
    }

    void deliver(const Endpoint& from, const hal::CanFrame& f) {
        ++frames;
        log.push_back(f);
        for (auto& e : endpoints_) {
            if (e.get() == &from) continue;
            if (drop && drop(f)) {
                ++lost;
                continue;
            }
            if (loss > 0 && static_cast<double>(random_() >> 11) * 0x1.0p-53 < loss) {
                ++lost;
                continue;
            }
            e->rx.push_back(f);
        }
    }

    MicrosecondClock clock;
    std::function<void()> service;
    std::function<bool(const hal::CanFrame&)> drop;
    std::uint64_t step_us = 100;
    std::uint64_t frames = 0, lost = 0;
    bool keep_log = false;
    double loss;                     ///< fraction of frame copies lost; may change between phases
    std::vector<hal::CanFrame> log;  // every frame sent (when keep_log)

private:
    friend class Endpoint;
    std::mt19937_64 random_;
    std::vector<std::unique_ptr<Endpoint>> endpoints_;
};

inline hal::CanSendResult Endpoint::send(const hal::CanFrame& frame) {
    if (state_ == hal::CanBusState::kBusOff) return hal::CanSendResult::kBusOff;
    hub_.deliver(*this, frame);
    if (!hub_.keep_log) hub_.log.clear();
    return hal::CanSendResult::kQueued;
}

inline bool Endpoint::receive(hal::CanFrame& out, std::uint32_t timeout_us) {
    std::uint64_t waited = 0;
    for (;;) {
        if (!rx.empty()) {
            out = rx.front();
            rx.pop_front();
            return true;
        }
        if (serviced_ && hub_.service) {
            hub_.service();
            if (!rx.empty()) continue;
        }
        if (waited >= timeout_us) return false;
        const std::uint64_t step = std::min<std::uint64_t>(hub_.step_us, timeout_us - waited);
        hub_.clock.advance(step);
        waited += step;
    }
}

/// A master endpoint and `nodes` simulated drives (node 1..n) at `start` positions.
struct Rig {
    explicit Rig(std::size_t nodes, const std::vector<std::int32_t>& start, double loss = 0,
                 std::uint64_t seed = 1, sim::Cia402DriveOptions base = {})
        : hub(loss, seed), master_bus(hub.add(true)) {
        for (std::size_t i = 0; i < nodes; ++i) {
            sim::Cia402DriveOptions o = base;
            o.node = static_cast<std::uint8_t>(i + 1);
            o.start_position = start.empty() ? 0 : start[i];
            drives.push_back(std::make_unique<sim::SimulatedCia402Drive>(hub.add(false), o));
        }
        hub.service = [this] {
            for (auto& d : drives) d->poll(hub.clock.now());
        };
    }
    Hub hub;
    Endpoint& master_bus;
    std::vector<std::unique_ptr<sim::SimulatedCia402Drive>> drives;
};

struct Job {
    host::MachineProfile machine;
    host::Plan plan;
};

inline Job plan_example(const std::string& name) {
    Job j;
    j.machine = host::load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) +
                                           "/examples/machines/pen_plotter.json");
    const host::Path path =
        host::load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/" + name);
    j.plan = host::plan_path(host::to_bezier_segments(path), j.machine);
    return j;
}

/// The core's setpoints of `plan` at ticks 0, c, 2c, ... below its length, then the end point:
/// what a CSP master with c ticks per cycle sends. Row-major, `axes` per row.
inline std::vector<std::int32_t> cycle_setpoints(const host::Plan& plan, std::size_t axes,
                                                 std::uint32_t c) {
    std::vector<std::int32_t> all;
    host::play_through_core(plan.spans, axes, [&](const host::PlayedTick& t) {
        all.insert(all.end(), t.setpoint, t.setpoint + axes);
    });
    const std::size_t ticks = all.size() / axes;  // total + 1 (the end point)
    std::vector<std::int32_t> out;
    for (std::size_t k = 0; k + 1 < ticks; k += c)
        out.insert(out.end(), all.begin() + k * axes, all.begin() + (k + 1) * axes);
    out.insert(out.end(), all.end() - static_cast<std::ptrdiff_t>(axes), all.end());
    return out;
}

}  // namespace cia402_test
