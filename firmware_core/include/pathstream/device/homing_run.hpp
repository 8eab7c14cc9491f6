// A homing run: several axes homed one after another on command, each by the HomingSequencer
// against its own switch. This is the bookkeeping only (which axes, in which order, how each
// ended); the port's I/O glue starts each axis's sequencer and reports its end, since only it
// reads the switches (sim/gpio's DeviceIo, a firmware's GPIO task).
#pragma once

#include <cstdint>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/homing.hpp"
#include "pathstream/status.hpp"

namespace pathstream::device {

/// One axis a device can home: how, and against which of its switches.
struct HomingAxis {
    HomingConfig config;
    LimitSide side = LimitSide::kNegative;
};

/// The axes a device can home (its plan, in order) and each axis's homing state. Task
/// context. Storage inline: one entry per axis.
template <unsigned Axes>
class HomingRun {
public:
    /// The plan: `count` axes in the order a run homes them (init). Entries beyond Axes, or
    /// naming an axis >= Axes or one already planned, are refused with kBadLimits and the plan
    /// is left empty.
    [[nodiscard]] Status set_plan(const HomingAxis* axes, unsigned count) {
        planned_ = 0;
        if (count > Axes) return Status::kBadLimits;
        unsigned mask = 0;
        for (unsigned i = 0; i < count; ++i) {
            const unsigned a = axes[i].config.axis;
            if (a >= Axes || (mask & (1u << a)) != 0) return Status::kBadLimits;
            mask |= 1u << a;
            plan_[i] = axes[i];
        }
        planned_ = count;
        return Status::kOk;
    }

    /// Axes the plan can home, as a bit mask.
    unsigned plannable() const {
        unsigned mask = 0;
        for (unsigned i = 0; i < planned_; ++i) mask |= 1u << plan_[i].config.axis;
        return mask;
    }

    /// Begins a run of the axes in `mask` (bit a: axis a; 0: the whole plan) in plan order.
    /// kNoHoming when the plan is empty or lacks one of them; kWrongState while a run goes on.
    /// Every axis of the run reports kHoming until its turn ends.
    [[nodiscard]] Status begin(unsigned mask) {
        if (busy()) return Status::kWrongState;
        const unsigned can = plannable();
        if (mask == 0) mask = can;
        if (mask == 0 || (mask & ~can) != 0) return Status::kNoHoming;
        pending_ = mask;
        current_ = -1;
        for (unsigned a = 0; a < Axes; ++a) {
            before_[a] = report_[a];
            if ((mask & (1u << a)) != 0) report_[a] = {AxisHoming::kHoming, HomingError::kNone};
        }
        return Status::kOk;
    }

    /// The next axis to home, taken off the run (null when none is left). The caller starts
    /// its sequencer and later calls finished() with how it ended.
    const HomingAxis* next() {
        for (unsigned i = 0; i < planned_; ++i) {
            const unsigned bit = 1u << plan_[i].config.axis;
            if ((pending_ & bit) != 0) {
                pending_ &= ~bit;
                current_ = static_cast<int>(i);
                return &plan_[i];
            }
        }
        current_ = -1;
        return nullptr;
    }

    /// The current axis's homing ended: kNone for zero set, else why it failed. A failure ends
    /// the run: the axes still waiting keep the state they had before it.
    void finished(HomingError error) {
        if (current_ < 0) return;
        const unsigned a = plan_[current_].config.axis;
        report_[a] = {error == HomingError::kNone ? AxisHoming::kHomed : AxisHoming::kFailed,
                      error};
        current_ = -1;
        if (error == HomingError::kNone) return;
        for (unsigned b = 0; b < Axes; ++b) {
            if ((pending_ & (1u << b)) != 0) report_[b] = before_[b];
        }
        pending_ = 0;
    }

    /// True from begin() until the last axis's finished() (or a failure).
    bool busy() const { return current_ >= 0 || pending_ != 0; }

    /// Axis `axis`'s homing state (kNotHomed for an axis >= Axes).
    HomingReport report(unsigned axis) const {
        return axis < Axes ? report_[axis] : HomingReport{};
    }

private:
    HomingAxis plan_[Axes] = {};
    unsigned planned_ = 0;
    unsigned pending_ = 0;  // axes of the run not yet started
    int current_ = -1;      // plan index of the axis homing now
    HomingReport report_[Axes] = {};
    HomingReport before_[Axes] = {};
};

}  // namespace pathstream::device
