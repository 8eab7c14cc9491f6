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

/// Encodes the spans of one job one after the other, as they come: T0 is left out
/// (kWireContinueTangent) wherever it equals the previous span's T1, the last span carries
/// kWireJobEnd (the device idles at its end and reports the job finished) and a span with
/// pause_after kWirePause. Owns nothing but the previous span's end; one thread.
class WireEncoder {
public:
    /// The wire bytes of the job's next span, `last` when it ends the job. Throws
    /// std::invalid_argument for 0 or more than 8 axes, a span of another basis or axis
    /// count, a span that does not start where the previous one ends, a pause or a job end
    /// not at rest, or a span that cannot be encoded. O(axes).
    std::vector<std::uint8_t> encode(const CoreSpan& span, bool last);
    /// Spans encoded so far.
    std::size_t count() const { return index_; }

private:
    std::size_t index_ = 0;
    unsigned axes_ = 0;
    std::int32_t previous_end_[8] = {};
    std::int32_t previous_tangent_[8] = {};
};

/// Encodes `plan` (Hermite spans that chain exactly, as plan_path makes them) as one job with
/// WireEncoder. Throws std::invalid_argument for an empty plan and as WireEncoder::encode.
WirePlan encode_wire_plan(const Plan& plan);

}  // namespace pathstream::host
