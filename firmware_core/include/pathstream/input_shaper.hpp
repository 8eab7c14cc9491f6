// Input shaping on the device: each axis's output is the exact weighted sum of its last
// setpoints at the shaper's tap delays, rounded once. The weights are positive and sum to one,
// so the shaped motion is an average of delayed copies of the command: it cancels the
// machine's ringing at the tuned frequency, and its velocity, acceleration and jerk never
// exceed the command's (docs/input-shaping.md).
#pragma once

#include <cstdint>

#include "pathstream/shaper_taps.hpp"
#include "pathstream/status.hpp"
#include "pathstream/units.hpp"

namespace pathstream {

/// round(sum of taps[i].weight * history[(head - taps[i].delay) & mask] / 2^16), halves up, in
/// 64-bit arithmetic: |weight * setpoint| < 2^16 * 2^31, and the weights sum to 2^16. One
/// signed multiply-accumulate per tap where the CPU has one (SMLAL on ARMv7-M). `count` >= 1.
/// Any context.
inline Lsb shaped_sum_wide(const ShaperTap* taps, std::uint32_t count, const Lsb* history,
                           std::uint32_t head, std::uint32_t mask) {
    std::int64_t sum = std::int64_t{1} << (kShaperWeightBits - 1);
    for (std::uint32_t t = 0; t < count; ++t) {
        // A weight is at most 2^16: signed, so that the product is one signed multiply-add.
        sum += static_cast<std::int64_t>(static_cast<std::int32_t>(taps[t].weight)) *
               history[(head - taps[t].delay) & mask];
    }
    // An arithmetic shift is floor division (C++20): the sum plus a half, floored.
    return static_cast<Lsb>(sum >> kShaperWeightBits);
}

/// shaped_sum_wide's value in 32-bit arithmetic only, for CPUs without a 32x32->64 multiply
/// (ARMv6-M calls a library routine for each). Each setpoint h splits into h = 2^16 hi + lo,
/// hi = h >> 16 (signed) and lo = h & 0xFFFF, so sum w h = 2^16 A + B with A = sum w hi and
/// B = sum w lo. B + 2^15 <= 2^16 (2^16 - 1) + 2^15 < 2^32 never overflows, and the result
/// A + floor((B + 2^15) / 2^16) lies between the smallest and largest setpoint summed, so
/// computing A modulo 2^32 gives it exactly for any int32 setpoints. `count` >= 1. Any
/// context.
inline Lsb shaped_sum_narrow(const ShaperTap* taps, std::uint32_t count, const Lsb* history,
                             std::uint32_t head, std::uint32_t mask) {
    std::uint32_t high = 0;  // two's complement of sum w hi: wraps only through the casts
    std::uint32_t low = std::uint32_t{1} << (kShaperWeightBits - 1);
    for (std::uint32_t t = 0; t < count; ++t) {
        const auto h = static_cast<std::uint32_t>(history[(head - taps[t].delay) & mask]);
        const std::uint32_t w = taps[t].weight;
        // h >> 16 as a signed value, in unsigned arithmetic (sign bits replicated by hand).
        const std::uint32_t hi = (h >> 16) | ((h & 0x80000000u) != 0 ? 0xFFFF0000u : 0u);
        high += w * hi;
        low += w * (h & 0xFFFFu);
    }
    return static_cast<Lsb>(high + (low >> kShaperWeightBits));
}

/// A shaper stage for `Axes` axes that remembers the last `HistoryTicks` setpoints of each
/// (a power of two: the longest tap delay is HistoryTicks - 1). RAM: 4 * HistoryTicks bytes per
/// axis plus 8 bytes per tap. Storage inline, no allocation. shape() runs in the tick
/// interrupt; configure() and reset() in the task that owns the stage while it is settled (or
/// in init), never concurrently with shape().
template <unsigned Axes, std::uint32_t HistoryTicks>
class InputShaper {
    static_assert(Axes >= 1, "at least one axis");
    static_assert(HistoryTicks >= 2 && (HistoryTicks & (HistoryTicks - 1)) == 0,
                  "HistoryTicks is a power of two");

public:
    /// Every axis unshaped (output = input) and at `position`. Init context.
    explicit InputShaper(const Lsb (&position)[Axes]) { reset(position); }

    /// Sets one axis's taps (count 0: no shaping on it). Only while settled(): then every
    /// remembered setpoint is the same, and the output goes on from it without a jump.
    /// kBadShaper for an axis out of range or taps check_shaper_taps refuses, kWrongState
    /// while the output still moves; nothing changes unless kOk. Cost: a copy of the taps.
    /// Task or init context.
    [[nodiscard]] Status configure(unsigned axis, const ShaperTap* taps, std::uint32_t count) {
        if (axis >= Axes) return Status::kBadShaper;
        const Status checked = check_shaper_taps(taps, count, HistoryTicks);
        if (checked != Status::kOk) return checked;
        if (!settled()) return Status::kWrongState;
        for (std::uint32_t i = 0; i < count; ++i) taps_[axis][i] = taps[i];
        tap_count_[axis] = count;
        longest_delay_ = 0;
        for (unsigned a = 0; a < Axes; ++a) {
            if (tap_count_[a] > 0 && taps_[a][tap_count_[a] - 1].delay > longest_delay_)
                longest_delay_ = taps_[a][tap_count_[a] - 1].delay;
        }
        return Status::kOk;
    }

    /// Forgets the history: every axis is at `position`, output = input, settled. For a jump
    /// the command makes without moving the machine (a new coordinate origin), which must not
    /// be smoothed into a motion. Cost: HistoryTicks stores per axis. Task or init context,
    /// never concurrently with shape().
    void reset(const Lsb (&position)[Axes]) {
        for (unsigned a = 0; a < Axes; ++a) {
            for (std::uint32_t k = 0; k < HistoryTicks; ++k) history_[a][k] = position[a];
        }
        still_ticks_ = HistoryTicks;
    }

    /// One tick: remembers `command` and writes each axis's shaped setpoint to `out`:
    /// round(sum of weight_i * command(now - delay_i) / kShaperWeightOne), halves rounded up,
    /// exactly (shaped_sum_wide; on ARMv6-M shaped_sum_narrow, the same value). Cost per axis:
    /// one store and per tap an index mask, two loads and a multiply-add (docs/cortex-m.md has
    /// the counts). Tick interrupt context.
    void shape(const Lsb (&command)[Axes], Lsb (&out)[Axes]) {
        const std::uint32_t previous = head_;
        head_ = (head_ + 1) & kMask;
        bool moved = false;
        for (unsigned a = 0; a < Axes; ++a) {
            Lsb* const history = history_[a];
            moved = moved || command[a] != history[previous];
            history[head_] = command[a];
            const std::uint32_t count = tap_count_[a];
            if (count == 0) {
                out[a] = command[a];
                continue;
            }
#if defined(__ARM_ARCH_6M__)
            out[a] = shaped_sum_narrow(taps_[a], count, history, head_, kMask);
#else
            out[a] = shaped_sum_wide(taps_[a], count, history, head_, kMask);
#endif
        }
        still_ticks_ = moved ? 0 : (still_ticks_ < HistoryTicks ? still_ticks_ + 1 : still_ticks_);
    }

    /// True when the output equals the command and stays so while the command rests: the
    /// command has not moved for the longest tap delay. Any context of the owner.
    bool settled() const {
        return still_ticks_ >= longest_delay_;
    }
    /// Ticks the output lags its settled state after the command stops: the longest delay.
    std::uint32_t longest_delay() const {
        return longest_delay_;
    }
    /// The taps of `axis` (tap_count(axis) of them). Any context of the owner.
    const ShaperTap* taps(unsigned axis) const {
        return taps_[axis];
    }
    std::uint32_t tap_count(unsigned axis) const {
        return tap_count_[axis];
    }
    static constexpr std::uint32_t history_ticks() {
        return HistoryTicks;
    }

private:
    static constexpr std::uint32_t kMask = HistoryTicks - 1;

    Lsb history_[Axes][HistoryTicks] = {};
    ShaperTap taps_[Axes][kMaxShaperTaps] = {};
    std::uint32_t tap_count_[Axes] = {};
    std::uint32_t head_ = 0;
    std::uint32_t longest_delay_ = 0;
    std::uint32_t still_ticks_ = 0;
};

}  // namespace pathstream
