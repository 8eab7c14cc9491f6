// Corner blending (corner_blend.cpp): a segment source between the reader and the grid, so
// that streamed jobs are blended as they are read.
#pragma once

#include <cstddef>
#include <deque>
#include <optional>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"

namespace pathstream::host::planner_detail {

/// Gives `inner`'s segments with every vertex between two straight segments of one run that
/// turn by more than 1e-6 and at most `stop_angle` rad replaced by a blend: the segments are
/// shortened by d each side and a quadratic Bezier (as a cubic) from V - d t1 over V to
/// V + d t2 joins them, tangent to both, passing `deviation` mm from the vertex (d =
/// 2 deviation / sin(turn / 2), at most half of each segment). Joints stay shared exactly.
class CornerBlender : public SegmentSource {
public:
    CornerBlender(SegmentSource& inner, double deviation, double stop_angle);
    bool next(BezierSegment& out) override;
    bool rewind() override;
    std::size_t size_hint() const override { return inner_.size_hint(); }

private:
    void blend(BezierSegment& b);

    SegmentSource& inner_;
    double deviation_, stop_angle_;
    std::deque<BezierSegment> ready_;
    std::optional<BezierSegment> held_;  ///< its end may still be shortened
    double held_original_length_ = -1;
};

}  // namespace pathstream::host::planner_detail
