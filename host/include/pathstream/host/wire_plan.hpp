// A plan as every streaming client sends it: one encoded wire span per plan span
// (firmware_core's wire_span.hpp), with the bookkeeping flow control needs.
#pragma once

#include <cstdint>
#include <vector>

#include "pathstream/host/plan.hpp"

namespace pathstream::host {

struct WirePlan {
    unsigned axes = 0;
    std::int32_t start[8] = {};                    ///< where the first span starts, LSB
    std::vector<std::vector<std::uint8_t>> spans;  ///< encoded wire spans, in plan order
    std::vector<std::uint64_t> prefix_ticks;       ///< prefix_ticks[i]: ticks of spans [0, i)
};

/// Encodes `plan` (Hermite spans that chain exactly, as plan_path makes them) as one job: T0
/// is left out (kWireContinueTangent) wherever it equals the previous span's T1, and the last
/// span carries kWireJobEnd (the device idles at its end and reports the job finished).
/// Throws std::invalid_argument for an empty plan, 0 or more than 8 axes, a span of another
/// basis, a span that does not start where the previous one ends, a plan that does not end
/// at rest, or a span that cannot be encoded.
WirePlan encode_wire_plan(const Plan& plan);

}  // namespace pathstream::host
