// The deviation's window over a streamed path: read ahead of the motion, dropped behind it.
#include "path_window.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace pathstream::host::planner_detail {

PathWindow::PathWindow(SegmentSource& source, double global_below,
                       std::function<void(const BezierSegment&)> on_read)
    : source_(source), global_below_(global_below), on_read_(std::move(on_read)) {}

PathWindow::~PathWindow() = default;

bool PathWindow::read_one() {
    BezierSegment s;
    if (exhausted_ || !source_.next(s)) {
        exhausted_ = true;
        return false;
    }
    if (on_read_) on_read_(s);
    if (!any_read_ || s.subpath != last_subpath_) seen_down_ = seen_up_ = false;
    any_read_ = true;
    last_subpath_ = s.subpath;
    (s.pen_down ? seen_down_ : seen_up_) = true;
    if (s.pen_down) {
        cubics_.push_back(to_cubic(s));
        index_.push_back(read_);
        subpath_.push_back(s.subpath);
    }
    ++read_;
    return true;
}

void PathWindow::prepare(std::size_t subpath, bool pen_down) {
    // Segments come in subpath order: past this subpath, or at its segment of this pen state,
    // its feed has been read.
    while (!exhausted_ &&
           !(any_read_ && (last_subpath_ > subpath ||
                           (last_subpath_ == subpath && (pen_down ? seen_down_ : seen_up_))))) {
        read_one();
    }
    if (!pen_down) return;
    if (!projector_) {
        if (!cubics_.empty()) rebuild();
        return;
    }
    const bool more = !exhausted_ || index_.back() > projector_last_;
    const std::size_t at = projector_->cursor().segment;
    if (subpath > projector_last_subpath_ || (more && projector_last_ - at < kAhead / 2)) rebuild();
}

void PathWindow::rebuild() {
    const PathProjector::Cursor cursor =
        projector_ ? projector_->cursor() : PathProjector::Cursor{};
    const std::size_t at = static_cast<std::size_t>(
        std::lower_bound(index_.begin(), index_.end(), cursor.segment) - index_.begin());
    const std::size_t drop = at > kBehind ? at - kBehind : 0;
    for (std::size_t k = 0; k < drop; ++k) {
        cubics_.pop_front();
        index_.pop_front();
        subpath_.pop_front();
    }
    while (!exhausted_ && cubics_.size() < (at - drop) + kAhead) read_one();
    if (cubics_.empty()) return;
    projector_ = std::make_unique<PathProjector>(
        std::vector<Cubic>(cubics_.begin(), cubics_.end()),
        std::vector<std::size_t>(index_.begin(), index_.end()), global_below_);
    projector_->resume(cursor);
    projector_last_ = index_.back();
    projector_last_subpath_ = subpath_.back();
}

}  // namespace pathstream::host::planner_detail
