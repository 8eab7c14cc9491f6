// A digital input a test drives: the simulated e-stop button or limit switch.
#pragma once

#include <cstdint>
#include <deque>

#include "pathstream/hal/gpio.hpp"

namespace pathstream::sim {

/// A DigitalInput whose level the test sets; every change queues an edge, as a kernel's event
/// buffer would. Host simulation only (a deque: may allocate).
class SimulatedInput final : public hal::DigitalInput {
public:
    /// Sets the level; a change queues an edge stamped `timestamp_ns`. Setting the same level
    /// again changes nothing (no edge), like a real line.
    void drive(bool active, std::uint64_t timestamp_ns = 0) {
        if (active == level_) return;
        level_ = active;
        edges_.push_back(hal::InputEdge{active, timestamp_ns});
    }
    /// A pulse shorter than anything polls: two edges, the level back where it was.
    void pulse(std::uint64_t timestamp_ns = 0) {
        drive(!level_, timestamp_ns);
        drive(!level_, timestamp_ns);
    }

    bool active() override { return level_; }
    bool next_edge(hal::InputEdge& edge) override {
        if (edges_.empty()) return false;
        edge = edges_.front();
        edges_.pop_front();
        return true;
    }

private:
    bool level_ = false;
    std::deque<hal::InputEdge> edges_;
};

}  // namespace pathstream::sim
