// The simulated device's timer: a tick counter that advances when asked, never sleeps.
#pragma once

#include <cstdint>

#include "pathstream/hal/clock.hpp"

namespace pathstream::sim {

/// A Clock that jumps: wait_until(k) sets now() to k at once (if k is ahead). The simulated
/// device's own tick counter, so a simulation runs as fast as the host computes it.
/// Header-only, no allocation, any context.
class VirtualClock final : public hal::Clock {
public:
    std::uint64_t now() const override { return now_; }
    void wait_until(std::uint64_t tick) override {
        if (tick > now_) now_ = tick;
    }

private:
    std::uint64_t now_ = 0;
};

}  // namespace pathstream::sim
