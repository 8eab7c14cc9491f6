// Pen-down runs -> Bezier-chain subpaths.
#include "runs.hpp"

#include <cstdint>
#include <stdexcept>
#include <string>

#include "pathstream/machine/input_error.hpp"

namespace pathstream::host::gcode {

PathPoint RunBuilder::point(const Axes& a) const {
    PathPoint p(path_axes_.size());
    for (std::size_t k = 0; k < path_axes_.size(); ++k) p[k] = a[path_axes_[k]];
    return p;
}

namespace {
/// A polyline run as the Bezier chain of its line pieces (a curve is joining it).
void to_bezier_chain(Subpath& run) {
    const std::size_t axes = run.points.axes();
    PointList chain(axes);
    chain.reserve(3 * run.points.size(), axes);
    chain.push_back(run.points.front());
    PathPoint p(axes);
    for (std::size_t i = 1; i < run.points.size(); ++i) {
        for (int third = 1; third <= 3; ++third) {
            for (std::size_t a = 0; a < axes; ++a) {
                const double from = run.points[i - 1][a], to = run.points[i][a];
                p[a] = third == 3 ? to : from + (third / 3.0) * (to - from);
            }
            chain.push_back(p);
        }
    }
    run.points = std::move(chain);
    run.basis = PathBasis::kBezier;
}

/// Whether the path's coordinates of `piece` are those of a straight piece (the other axes
/// may move: they are not on the path).
bool path_line(const PathPoint& p0, const PathPoint& p1, const PathPoint& p2, const PathPoint& p3) {
    for (std::size_t a = 0; a < p0.size(); ++a) {
        if (p1[a] != p0[a] + (1.0 / 3.0) * (p3[a] - p0[a]) ||
            p2[a] != p0[a] + (2.0 / 3.0) * (p3[a] - p0[a])) {
            return false;
        }
    }
    return true;
}
}  // namespace

void RunBuilder::draw(const Piece& piece, double feed_mm_s, SourceLocation at,
                      const std::string& file) {
    add(piece, feed_mm_s, false, at, file);
}

void RunBuilder::travel(const Piece& piece, double feed_mm_s, SourceLocation at,
                        const std::string& file) {
    add(piece, feed_mm_s, true, at, file);
}

void RunBuilder::add(const Piece& piece, double feed_mm_s, bool travel, SourceLocation at,
                     const std::string& file) {
    const PathPoint p0 = point(piece.p[0]), p1 = point(piece.p[1]), p2 = point(piece.p[2]),
                    p3 = point(piece.p[3]);
    if (p1 == p0 && p2 == p0 && p3 == p0) return;  // zero length on the path's axes
    if (++pieces_ > max_pieces_) {
        throw InputError(file, at,
                         "more than " + std::to_string(max_pieces_) +
                             " curve pieces drawn (the reader's limit)");
    }
    if (open_ && (done_.back().travel != travel || done_.back().feed != feed_mm_s ||
                  done_.back().corner_mode != corner_mode_ ||
                  done_.back().blend_tolerance != blend_tolerance_)) {
        close_run();  // one feed and one path control mode per subpath
    }
    const bool line = path_line(p0, p1, p2, p3);
    if (!open_) {
        Subpath sp;
        sp.basis = line ? PathBasis::kPolyline : PathBasis::kBezier;
        sp.closed = false;
        sp.travel = travel;
        sp.feed = feed_mm_s;
        sp.location = at;
        sp.pause_before = pause_next_;
        sp.pause_note = pause_next_ ? std::move(pause_note_) : std::string();
        sp.outputs = outputs_;
        sp.pause_outputs = pause_next_ ? pause_outputs_ : outputs_;
        sp.dwell_before = dwell_next_;
        sp.dwell_pen_down = dwell_pen_down_;
        sp.corner_mode = corner_mode_;
        sp.blend_tolerance = blend_tolerance_;
        pause_next_ = false;
        dwell_next_ = 0;
        dwell_pen_down_ = false;
        sp.points = PointList(path_axes_.size());
        sp.points.push_back(p0);
        done_.push_back(std::move(sp));
        open_ = true;
    } else if (done_.back().points.back() != p0) {
        throw std::logic_error("RunBuilder::draw: piece does not start where the run ends");
    }
    Subpath& run = done_.back();
    // One curve segment per piece, as a polyline and as a Bezier chain alike.
    run.segment_lines.push_back(static_cast<std::uint32_t>(at.line));
    if (run.basis == PathBasis::kPolyline && line) {
        run.points.push_back(p3);  // the planner makes the same cubic of it
        return;
    }
    if (run.basis == PathBasis::kPolyline) to_bezier_chain(run);
    run.points.push_back(p1);
    run.points.push_back(p2);
    run.points.push_back(p3);
}

void RunBuilder::end_block() {
    if (!open_ || corner_mode_ != CornerMode::kExactStop) return;
    Subpath& run = done_.back();
    const auto joint = static_cast<std::uint32_t>(chain_segments(run));
    if (joint > 0 && (run.stops.empty() || run.stops.back() != joint)) run.stops.push_back(joint);
}

void RunBuilder::close_run() {
    if (open_ && !done_.back().stops.empty() &&
        done_.back().stops.back() >= chain_segments(done_.back())) {
        done_.back().stops.pop_back();
    }
    open_ = false;
}

void RunBuilder::lift() {
    close_run();
}

std::vector<Subpath> RunBuilder::finish() {
    close_run();
    return std::move(done_);
}

}  // namespace pathstream::host::gcode
