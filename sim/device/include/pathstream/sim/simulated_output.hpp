// A digital output that records when it switched, in ticks of a clock.
#pragma once

#include <cstdint>
#include <vector>

#include "pathstream/hal/clock.hpp"
#include "pathstream/hal/digital_output.hpp"

namespace pathstream::sim {

/// A DigitalOutput (the pen lift, in the simulated plotter) that keeps its state and the
/// clock tick of every change. Starts inactive (pen up). set() appends to a vector only when
/// the state changes (amortised O(1); may allocate: host simulation only).
class SimulatedOutput final : public hal::DigitalOutput {
public:
    /// `clock` stamps the switches; it must outlive this output.
    explicit SimulatedOutput(const hal::Clock& clock) : clock_(clock) {}

    void set(bool active) override {
        if (active == state_) return;
        state_ = active;
        switch_ticks_.push_back(clock_.now());
    }

    bool state() const { return state_; }
    /// Tick of every change, in order: the first is a switch to active.
    const std::vector<std::uint64_t>& switch_ticks() const { return switch_ticks_; }

private:
    const hal::Clock& clock_;
    bool state_ = false;
    std::vector<std::uint64_t> switch_ticks_;
};

}  // namespace pathstream::sim
