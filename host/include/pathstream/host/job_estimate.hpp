// How long a job runs before it is planned: from the path's length and feeds, then refined by
// what planning has made of the part planned so far.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// A model of a job's duration built once from its segments (O(segments), no planning): each
/// segment's length (the mean of its chord and control polygon) at its requested feed, capped
/// by the axes' speeds along its chord, plus a stop and a start (v / a) wherever the motion
/// comes to rest (pen changes, pauses, exact stops) and every dwell. The planner's corners make
/// the real job longer; total_ticks() corrects the model with the part already planned.
class JobEstimate {
public:
    JobEstimate(const std::vector<BezierSegment>& segments, const MachineProfile& profile);
    /// The same from every segment of `source`, which is rewound after (16 bytes a segment).
    JobEstimate(SegmentSource& source, const MachineProfile& profile);

    /// The model's seconds for the whole job.
    double model_seconds() const { return seconds_.back(); }
    /// The model's mm of path (drawn and travel) for the whole job.
    double model_length_mm() const { return length_.back(); }

    /// The job's ticks, estimated from the `planned_mm` of path planned so far in
    /// `planned_ticks`: those ticks, plus the model's time for the rest scaled by how much
    /// longer (or shorter) the planner made the planned part than the model. With nothing
    /// planned: the model alone. O(log segments).
    std::uint64_t total_ticks(double planned_mm, std::uint64_t planned_ticks) const;

private:
    void add(SegmentSource& source, const MachineProfile& profile);

    std::vector<double> length_;   ///< mm of path before segment k (k = 0 .. segments)
    std::vector<double> seconds_;  ///< the model's seconds before segment k
    double tick_hz_;
};

}  // namespace pathstream::host
