// Step/dir outputs from setpoints: each tick, an axis moves by its setpoint difference, one
// step pulse per LSB (a step/dir machine's profile makes one LSB one microstep of its
// driver), the pulses spread evenly across the tick and the direction set at the tick's start.
// Integer only, one 32-bit division per axis and tick, then an add per pulse: what a timer
// compare interrupt can afford on a Cortex-M0+.
#pragma once

#include <cstdint>

namespace pathstream::device {

/// Most steps one axis may make in one tick: the schedule's remainders stay within 32 bits.
inline constexpr std::uint32_t kMaxStepsPerTick = 0x3FFFFFFFu;

/// Why a step timing does not fit (step_timing_check).
enum class StepTimingResult : std::uint8_t {
    kOk = 0,
    kNoPeriod,          ///< the tick period is 0 timer counts
    kPeriodTooLong,     ///< the period needs more than 31 bits of timer counts
    kNoSteps,           ///< the maximum steps per tick is 0
    kTooManySteps,      ///< more steps per tick than timer counts in a tick, or 2^30 or more
    kPulsesTooClose,    ///< pulses at the maximum rate come closer than the driver allows
    kDirSetupTooShort,  ///< the first pulse of a tick comes before the direction has settled
};

/// Whether step pulses at up to `max_steps` per tick of `period` timer counts keep a driver's
/// timing: every two pulses (in one tick or across a tick boundary) at least `min_spacing`
/// counts apart, and the first pulse of a tick at least `dir_setup` counts after the tick's
/// start, where the direction changes. StepSchedule guarantees the gaps floor(period /
/// max_steps) and floor(period / (2 max_steps)) that this compares. Init context; constant time.
[[nodiscard]] constexpr StepTimingResult step_timing_check(std::uint32_t period,
                                                           std::uint32_t max_steps,
                                                           std::uint32_t min_spacing,
                                                           std::uint32_t dir_setup) {
    if (period == 0) return StepTimingResult::kNoPeriod;
    if (period > 0x7FFFFFFFu) return StepTimingResult::kPeriodTooLong;
    if (max_steps == 0) return StepTimingResult::kNoSteps;
    if (max_steps > period || max_steps > kMaxStepsPerTick) return StepTimingResult::kTooManySteps;
    if (period / max_steps < min_spacing) return StepTimingResult::kPulsesTooClose;
    if (period / (2u * max_steps) < dir_setup) return StepTimingResult::kDirSetupTooShort;
    return StepTimingResult::kOk;
}

/// One axis's step pulses within one tick: pulse i of `count` at floor((2i + 1) period /
/// (2 count)) counts from the tick's start, centred in its share of the tick. Consecutive
/// pulses are floor(period / count) or one more apart; across a tick boundary the gap is at
/// least floor(period / max(count, next count)); the first pulse comes floor(period / (2
/// count)) after the start. Plain value; tick context; no division after begin().
class StepSchedule {
public:
    /// Starts a tick of `period` counts (at most 2^31 - 1) in which the axis moves by
    /// `difference` steps, at most `period` and kMaxStepsPerTick of them (step_timing_check).
    /// Returns false, and
    /// schedules nothing, when the difference breaks those bounds. One division.
    [[nodiscard]] constexpr bool begin(std::uint32_t period, std::int32_t difference) {
        const std::uint32_t count = difference < 0 ? 0u - static_cast<std::uint32_t>(difference)
                                                   : static_cast<std::uint32_t>(difference);
        left_ = 0;
        if (period == 0 || period > 0x7FFFFFFFu || count > period || count > kMaxStepsPerTick)
            return false;
        forward_ = difference >= 0;
        left_ = count;
        if (count == 0) return true;
        twice_count_ = 2u * count;
        step_ = period / count;
        const std::uint32_t rest = period % count;
        step_remainder_ = 2u * rest;
        // period = step_ count + rest, so period / (2 count) is step_ / 2 and its remainder
        // (step_ odd) count + rest: no second division.
        offset_ = step_ / 2u;
        remainder_ = (step_ & 1u) * count + rest;
        return true;
    }

    /// The direction level for this tick (true: positive difference), to set at its start.
    constexpr bool forward() const { return forward_; }
    /// Pulses not yet taken in this tick.
    constexpr std::uint32_t left() const { return left_; }

    /// Takes the next pulse's offset from the tick's start, in counts; false when the tick has
    /// no pulse left. Two additions and a compare.
    [[nodiscard]] constexpr bool next(std::uint32_t& offset) {
        if (left_ == 0) return false;
        offset = offset_;
        --left_;
        offset_ += step_;
        remainder_ += step_remainder_;
        if (remainder_ >= twice_count_) {
            ++offset_;
            remainder_ -= twice_count_;
        }
        return true;
    }

private:
    // offset_ and remainder_ are the quotient and remainder of (2i + 1) period by 2 count for
    // the next pulse i; each pulse adds 2 period, split the same way into step_, step_remainder_.
    std::uint32_t offset_ = 0;
    std::uint32_t remainder_ = 0;
    std::uint32_t step_ = 0;
    std::uint32_t step_remainder_ = 0;
    std::uint32_t twice_count_ = 0;
    std::uint32_t left_ = 0;
    bool forward_ = true;
};

/// Every axis's step pulses within one tick, merged into groups that rise together: the
/// earliest pending pulse and every other axis's next pulse within `window` counts after it
/// (a pulse moves earlier by less than the window, never later, and never ahead of its own
/// axis's previous pulse). One step timer compare per group instead of one per pulse. Plain
/// value; tick and step-timer contexts at one interrupt priority (neither preempts the other).
template <unsigned Axes>
class StepPulseTrain {
    static_assert(Axes >= 1 && Axes <= 32, "one bit per axis in a mask");

public:
    /// Starts a tick of `period` counts with each axis's setpoint difference. Returns false,
    /// and schedules nothing on any axis, when a difference breaks StepSchedule's bounds.
    /// Axes divisions.
    [[nodiscard]] constexpr bool begin(std::uint32_t period,
                                       const std::int32_t (&difference)[Axes]) {
        forward_ = 0;
        for (unsigned a = 0; a < Axes; ++a) {
            if (!schedule_[a].begin(period, difference[a])) {
                for (unsigned b = 0; b < Axes; ++b) pending_[b] = false;
                for (unsigned b = 0; b <= a; ++b) (void)schedule_[b].begin(period, 0);
                return false;
            }
            if (schedule_[a].forward()) forward_ |= 1u << a;
            pending_[a] = schedule_[a].next(next_[a]);
        }
        return true;
    }

    /// Bit a set: axis a moves forward (or not at all) this tick; its direction line's level.
    constexpr std::uint32_t forward_mask() const { return forward_; }

    /// The next group: `offset` (counts from the tick's start) of its earliest pulse and the
    /// `mask` of axes stepping in it. False when the tick has no pulse left. At most Axes
    /// compares and one StepSchedule::next per axis in the group.
    [[nodiscard]] constexpr bool next(std::uint32_t window, std::uint32_t& offset,
                                      std::uint32_t& mask) {
        bool any = false;
        for (unsigned a = 0; a < Axes; ++a) {
            if (pending_[a] && (!any || next_[a] < offset)) {
                offset = next_[a];
                any = true;
            }
        }
        if (!any) return false;
        mask = 0;
        for (unsigned a = 0; a < Axes; ++a) {
            if (pending_[a] && next_[a] - offset <= window) {
                mask |= 1u << a;
                pending_[a] = schedule_[a].next(next_[a]);
            }
        }
        return true;
    }

    /// Pulses not yet taken, all axes.
    constexpr std::uint32_t left() const {
        std::uint32_t n = 0;
        for (unsigned a = 0; a < Axes; ++a) n += schedule_[a].left() + (pending_[a] ? 1u : 0u);
        return n;
    }

private:
    StepSchedule schedule_[Axes] = {};
    std::uint32_t next_[Axes] = {};
    bool pending_[Axes] = {};
    std::uint32_t forward_ = 0;
};

}  // namespace pathstream::device
