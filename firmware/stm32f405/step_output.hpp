// Step/dir pins from the setpoints: each tick sets the direction lines at its start and
// spreads the axes' steps across the tick (StepPulseTrain), raised by TIM2's compare channel 1
// and lowered a pulse width later by channel 2. On the qemu model, whose timers raise no
// compare interrupts, each tick's train is still begun (its divisions are in the tick's cost)
// and its steps counted, but no pulse is raised.
#pragma once

#include <atomic>
#include <cstdint>

#include "board.hpp"
#include "pathstream/device/step_pulses.hpp"
#include "pathstream/hal/machine_lines.hpp"
#include "pins.hpp"
#include "registers.hpp"

namespace firmware {

template <unsigned Axes>
class StepOutput {
    using Tim2 = stm32::Timer<stm32::kTim2>;
    using Lines = pins::StepDirPins<Axes>;
    static_assert(pathstream::hal::StepDirLines<Lines>);

public:
    /// Whether pulses reach the pins (TIM2 compare interrupts exist).
    static constexpr bool kEnabled = !board::kQemu;

    /// The tick period in TIM2 counts. Tick interrupt (or init, before it runs).
    void set_period(std::uint32_t counts) { period_ = counts; }

    /// Starts a tick's pulses at TIM2 count `tick_start`: directions first, the first pulse
    /// at least the direction setup later (step_timing_check). Pulses of the last tick still
    /// pending are dropped and counted (the tick came before they were out). Tick interrupt.
    void start_tick(const std::int32_t (&difference)[Axes], std::uint32_t tick_start) {
        if (kEnabled && train_.left() != 0) bump(late_);
        if (!train_.begin(period_, difference)) {
            bump(refused_);
            return;
        }
        for (unsigned a = 0; a < Axes; ++a) {
            net_[a].store(net_[a].load(std::memory_order_relaxed) + difference[a],
                          std::memory_order_relaxed);
        }
        lines_.set_directions(train_.forward_mask());
        if constexpr (!kEnabled) return;  // the schedule is made; nothing raises its pulses
        tick_start_ = tick_start;
        Tim2::Dier::clear_bits(stm32::kTimDierCc1ie | stm32::kTimDierCc2ie);
        lines_.lower_steps(all_axes());
        schedule_next();
    }

    /// TIM2's compare interrupt: raises a group's step pins (channel 1) or lowers them and
    /// schedules the next group (channel 2). Step interrupt, the tick's priority.
    void on_compare() {
        const std::uint32_t sr = Tim2::Sr::read();
        if ((sr & stm32::kTimSrCc1if) != 0 && (Tim2::Dier::read() & stm32::kTimDierCc1ie) != 0) {
            Tim2::Sr::write(~stm32::kTimSrCc1if);
            lines_.raise_steps(group_);
            Tim2::Dier::clear_bits(stm32::kTimDierCc1ie);
            arm(Tim2::Ccr2::ref(), Tim2::Cnt::read() + board::kStepPulseCounts);
            Tim2::Dier::set_bits(stm32::kTimDierCc2ie);
        }
        if ((sr & stm32::kTimSrCc2if) != 0 && (Tim2::Dier::read() & stm32::kTimDierCc2ie) != 0) {
            Tim2::Sr::write(~stm32::kTimSrCc2if);
            lines_.lower_steps(group_);
            Tim2::Dier::clear_bits(stm32::kTimDierCc2ie);
            schedule_next();
        }
    }

    /// Stops the pulses and lowers the step pins. Any context.
    void halt() {
        if constexpr (kEnabled) Tim2::Dier::clear_bits(stm32::kTimDierCc1ie | stm32::kTimDierCc2ie);
        lines_.lower_steps(all_axes());
    }

    /// Steps made on `axis` since reset, forward minus backward. Any context.
    std::int32_t net_steps(unsigned axis) const {
        return net_[axis].load(std::memory_order_relaxed);
    }
    /// Ticks whose pulses were not all out when the next tick began; ticks refused by the
    /// train (a difference over the tick's counts: the limits allow none).
    std::uint32_t late_ticks() const { return late_.load(std::memory_order_relaxed); }
    std::uint32_t refused_ticks() const { return refused_.load(std::memory_order_relaxed); }

private:
    static constexpr std::uint32_t all_axes() { return (1u << Axes) - 1u; }
    static void bump(std::atomic<std::uint32_t>& c) {
        c.store(c.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
    }
    // A compare at `at`, or a little after now when `at` has passed already (a compare in the
    // past would wait for the counter's wrap).
    static void arm(volatile std::uint32_t& ccr, std::uint32_t at) {
        constexpr std::uint32_t kMargin = 32;
        const std::uint32_t soonest = Tim2::Cnt::read() + kMargin;
        ccr = static_cast<std::int32_t>(at - soonest) < 0 ? soonest : at;
    }
    void schedule_next() {
        std::uint32_t offset = 0;
        if (!train_.next(board::kStepPulseCounts, offset, group_)) return;
        const std::uint32_t earliest = board::kDirSetupCounts;
        arm(Tim2::Ccr1::ref(), tick_start_ + (offset < earliest ? earliest : offset));
        Tim2::Sr::write(~stm32::kTimSrCc1if);
        Tim2::Dier::set_bits(stm32::kTimDierCc1ie);
    }

    pathstream::device::StepPulseTrain<Axes> train_;  // tick and step interrupts (one level)
    Lines lines_;
    std::uint32_t period_ = 1;
    std::uint32_t tick_start_ = 0;
    std::uint32_t group_ = 0;
    std::atomic<std::int32_t> net_[Axes] = {};
    std::atomic<std::uint32_t> late_{0};
    std::atomic<std::uint32_t> refused_{0};
};

}  // namespace firmware
