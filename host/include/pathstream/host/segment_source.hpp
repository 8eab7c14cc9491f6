// A path's Bezier segments handed out one at a time (SegmentSource), so that neither the
// planner nor its check needs the whole list in memory: from a list held in memory, or made
// from a Path as they are asked for.
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// Gives the path's Bezier segments in order, one at a time, so that a job need not be held
/// whole in memory. Called from the planning thread only.
class SegmentSource {
public:
    virtual ~SegmentSource() = default;
    /// The next segment into `out`; false at the end of the path.
    virtual bool next(BezierSegment& out) = 0;
    /// Back to the first segment (for a replan); false when the source cannot rewind.
    virtual bool rewind() = 0;
    /// Number of segments when known (for progress), else 0.
    virtual std::size_t size_hint() const { return 0; }
};

/// A SegmentSource over segments held in memory (not copied: `segments` must outlive it).
class VectorSegmentSource : public SegmentSource {
public:
    explicit VectorSegmentSource(const std::vector<BezierSegment>& segments)
        : segments_(segments) {}
    bool next(BezierSegment& out) override {
        if (next_ >= segments_.size()) return false;
        out = segments_[next_++];
        return true;
    }
    bool rewind() override {
        next_ = 0;
        return true;
    }
    std::size_t size_hint() const override { return segments_.size(); }

private:
    const std::vector<BezierSegment>& segments_;
    std::size_t next_ = 0;
};

/// The segments of to_bezier_segments(path) (after a lead-in, when given), made as they are
/// asked for: memory O(1) whatever the path's length (the path itself is not copied and must
/// outlive the source). next() throws std::invalid_argument as to_bezier_segments does, at
/// the subpath that is wrong.
class PathSegmentSource : public SegmentSource {
public:
    /// `lead_in_from` (optional, mm per axis): a straight pen-up move from there to the path's
    /// start comes first, as prepend_lead_in makes it (none when it is the start already).
    explicit PathSegmentSource(const Path& path, std::optional<PathPoint> lead_in_from = {});
    bool next(BezierSegment& out) override;
    bool rewind() override;
    /// Counted once, on the first call (a pass over the subpaths' point counts).
    std::size_t size_hint() const override;

private:
    using Controls = std::array<PathPoint, 4>;
    /// Segment k of subpath s_ with its joints shared, its flags set; advances k_.
    void make_segment(BezierSegment& out);
    /// Number of curve segments of subpath s_ (throws when it has too few points).
    std::size_t begin_subpath();

    const Path& path_;
    std::optional<PathPoint> lead_in_from_;
    bool lead_in_done_ = false;
    std::size_t s_ = 0, k_ = 0, count_ = 0;
    bool in_subpath_ = false;
    bool any_ = false;  ///< a drawing segment was handed out
    PathPoint last_end_, first_start_, previous_end_;
    std::optional<BezierSegment> held_;  ///< a segment that waits behind a travel
    std::size_t next_stop_ = 0;
    mutable std::size_t size_ = 0;
    mutable bool sized_ = false;
};

}  // namespace pathstream::host
