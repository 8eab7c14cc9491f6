// The pen-down path around the motion, read from a SegmentSource as a streamed plan's check
// goes (path_window.cpp), so that the deviation is measured without the whole path in memory.
#pragma once

#include <cstddef>
#include <deque>
#include <functional>
#include <memory>

#include "cubic.hpp"
#include "pathstream/host/segment_source.hpp"
#include "projection.hpp"

namespace pathstream::host::planner_detail {

/// Segments read from a source in order, each handed to `on_read` (the check's feeds), the
/// pen-down ones kept from kBehind before the deviation's cursor to kAhead after it: the
/// projector measures against those. Memory O(kBehind + kAhead) segments, not O(path).
/// A distance is then the one to the path near the motion, never below the true distance
/// to the whole path (check_plan, which holds every segment, measures that).
class PathWindow {
public:
    static constexpr std::size_t kBehind = 1024, kAhead = 4096;

    PathWindow(SegmentSource& source, double global_below,
               std::function<void(const BezierSegment&)> on_read);
    ~PathWindow();
    PathWindow(const PathWindow&) = delete;
    PathWindow& operator=(const PathWindow&) = delete;

    /// Before a span of `subpath` with pen state `pen_down` is checked: reads until that
    /// subpath's first segment of that pen state has been read (so its feed is known) and, for
    /// a pen-down span, moves the projector's window along when the cursor nears its end.
    void prepare(std::size_t subpath, bool pen_down);
    /// The projector over the segments around the motion; null before any pen-down segment.
    PathProjector* projector() { return projector_.get(); }

private:
    bool read_one();
    /// Drops the segments more than kBehind before the cursor, reads up to kAhead after it and
    /// builds the projector over them, continuing from the old one's cursor.
    void rebuild();

    SegmentSource& source_;
    double global_below_;
    std::function<void(const BezierSegment&)> on_read_;
    std::deque<Cubic> cubics_;       ///< the pen-down segments held...
    std::deque<std::size_t> index_;  ///< ...their indices in the source's order
    std::deque<std::size_t> subpath_;
    std::size_t read_ = 0;  ///< segments read
    bool exhausted_ = false;
    bool any_read_ = false;
    std::size_t last_subpath_ = 0;
    bool seen_down_ = false, seen_up_ = false;  ///< for last_subpath_
    std::unique_ptr<PathProjector> projector_;
    std::size_t projector_last_ = 0;          ///< index of its last segment
    std::size_t projector_last_subpath_ = 0;  ///< and that segment's subpath
};

}  // namespace pathstream::host::planner_detail
