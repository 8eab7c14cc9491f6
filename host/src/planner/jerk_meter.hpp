// The jerk figures of a plan: the constant jerk inside each span's exact cubic and the
// acceleration step at every join, rest included, per axis (docs/planner.md, section 7).
#pragma once

#include <cstdint>
#include <vector>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host::planner_detail {

/// Follows a plan's spans in order and measures, from each span's exact integer cubic, its
/// constant jerk and the acceleration step where it joins the previous span (rest before the
/// first span and after a span with pause_after). `profile` must outlive it.
class JerkMeter {
public:
    explicit JerkMeter(const MachineProfile& profile);
    /// The next span of the plan (validated: its cubic and timing set).
    void span(const CoreSpan& span);
    /// Adds the join with rest after the last span and writes the figures into `out`; with a
    /// max_jerk on some axis, clears out.within_limits when a figure is over 1.
    void finish(PlanCheck& out) const;

private:
    /// An acceleration in LSB/tick^2 as the exact fraction numerator / denominator.
    struct Acceleration {
        std::int64_t numerator = 0;
        std::uint64_t denominator = 1;
    };
    void join(std::size_t axis, const Acceleration& next, const Acceleration& previous,
              std::vector<double>& step) const;

    const MachineProfile& profile_;
    std::size_t axes_;
    std::vector<double> jerk_lsb_, step_lsb_, limit_lsb_;
    std::vector<Acceleration> previous_end_;  ///< the last span's end (rest after a pause)
    bool any_span_ = false;
};

}  // namespace pathstream::host::planner_detail
