// Device ticks from a free-running hardware counter. A tick interrupt that counted its own
// entries would lose a tick whenever an entry came late or was merged with the next (an
// emulated timer loses 10 to 55 % of them); deriving the ticks from the counter instead keeps
// the device's time exact: each entry runs the ticks that came due since the last one.
#pragma once

#include <cstdint>

namespace pathstream::device {

/// Whole ticks of `tick_hz` in the time a free-running 32-bit counter of `counter_hz` has
/// advanced, with the remainder carried exactly (no drift, no rounding). Plain value; the
/// tick interrupt is its only user. Integer only: a loop of at most `max_ticks` subtractions
/// per call; a 64-bit division only when the backlog overflows.
class TickClock {
public:
    /// Most ticks owed at once: beyond it, the backlog (the tick could not keep up, or the
    /// counter was not read for a long time) is dropped and counted rather than run back to back.
    static constexpr std::uint32_t kMaxBacklog = 1000;

    /// Starts counting at counter value `now`: the first tick comes due one period later.
    /// `counter_hz` >= `tick_hz` > 0 (false, and nothing changes, otherwise). Init or tick context.
    [[nodiscard]] constexpr bool start(std::uint32_t counter_hz, std::uint32_t tick_hz,
                                       std::uint32_t now) {
        if (tick_hz == 0 || counter_hz < tick_hz) return false;
        counter_hz_ = counter_hz;
        tick_hz_ = tick_hz;
        last_ = now;
        owed_ = 0;
        return true;
    }

    /// Another tick rate from now on; the part of a period already elapsed is kept as the
    /// same fraction of the new period (a period is always counter_hz_ units of owed_). Same
    /// bounds as start(). Tick context.
    [[nodiscard]] constexpr bool retune(std::uint32_t tick_hz, std::uint32_t now) {
        if (tick_hz == 0 || counter_hz_ < tick_hz) return false;
        collect(now);
        tick_hz_ = tick_hz;
        return true;
    }

    /// The ticks that came due up to counter value `now`, at most `max_ticks`; the rest stay
    /// owed for the next call. The counter must be read at least once every 2^32 counts (its
    /// wrap), which a tick interrupt does many times over. Tick context.
    constexpr std::uint32_t advance(std::uint32_t now, std::uint32_t max_ticks) {
        collect(now);
        std::uint32_t due = 0;
        while (due < max_ticks && owed_ >= counter_hz_) {
            owed_ -= counter_hz_;
            ++due;
        }
        return due;
    }

    /// Ticks dropped because the backlog passed kMaxBacklog.
    constexpr std::uint32_t dropped() const { return dropped_; }
    constexpr std::uint32_t tick_hz() const { return tick_hz_; }

private:
    constexpr void collect(std::uint32_t now) {
        const std::uint32_t elapsed = now - last_;  // modulo 2^32: the counter's wrap
        last_ = now;
        owed_ += static_cast<std::uint64_t>(elapsed) * tick_hz_;
        const std::uint64_t limit = static_cast<std::uint64_t>(kMaxBacklog) * counter_hz_;
        if (owed_ >= limit + counter_hz_) {  // rare: one division only then
            const std::uint64_t excess = (owed_ - limit) / counter_hz_;
            owed_ -= excess * counter_hz_;
            const std::uint64_t room = 0xFFFFFFFFu - dropped_;
            dropped_ += static_cast<std::uint32_t>(excess < room ? excess : room);
        }
    }

    // owed_ counts time in units of 1 / (counter_hz_ * tick_hz_) s: a tick is counter_hz_ of
    // them, a counter count tick_hz_ of them, so both are whole numbers.
    std::uint64_t owed_ = 0;
    std::uint32_t counter_hz_ = 1;
    std::uint32_t tick_hz_ = 0;
    std::uint32_t last_ = 0;
    std::uint32_t dropped_ = 0;
};

}  // namespace pathstream::device
