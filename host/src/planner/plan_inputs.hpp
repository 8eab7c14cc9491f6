// What plan_path and plan_stream both derive from the profile and check before planning
// (plan_path.cpp).
#pragma once

#include <cstdint>

#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host::planner_detail {

/// `options` with what the machine profile sets itself (its corner_stop_angle, when given).
PlanOptions profile_options(const PlanOptions& options, const MachineProfile& profile);
/// The profile and options plan_path accepts (PlanError otherwise).
void validate_plan_inputs(const MachineProfile& profile, const PlanOptions& options);
/// Ticks of a regular span for `profile` (docs/planner.md §5, span length).
std::uint32_t regular_span_ticks(const MachineProfile& profile);

}  // namespace pathstream::host::planner_detail
