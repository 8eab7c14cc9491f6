// Pen-down runs -> Bezier-chain subpaths.
#include "runs.hpp"

#include <cstdint>
#include <stdexcept>
#include <string>

#include "pathstream/machine/input_error.hpp"

namespace pathstream::host::gcode {

namespace {
PathPoint point(Vec2 v) {
    return PathPoint{v.x, v.y};
}

Vec2 vec(PointRef p) {
    return {p[0], p[1]};
}

/// A polyline run as the Bezier chain of its line pieces (a curve is joining it).
void to_bezier_chain(Subpath& run) {
    PointList chain(2);
    chain.reserve(3 * run.points.size(), 2);
    chain.push_back(run.points.front());
    for (std::size_t i = 1; i < run.points.size(); ++i) {
        const Cubic line = line_piece(vec(run.points[i - 1]), vec(run.points[i]));
        for (std::size_t k = 1; k < line.p.size(); ++k) chain.push_back({line.p[k].x, line.p[k].y});
    }
    run.points = std::move(chain);
    run.basis = PathBasis::kBezier;
}
}  // namespace

void RunBuilder::draw(const Cubic& piece, double feed_mm_s, SourceLocation at,
                      const std::string& file) {
    const Vec2 p0 = piece.p[0];
    if (piece.p[1] == p0 && piece.p[2] == p0 && piece.p[3] == p0) return;  // zero length
    if (++pieces_ > kMaxPieces) {
        throw InputError(
            file, at,
            "more than " + std::to_string(kMaxPieces) + " curve pieces drawn (the reader's limit)");
    }
    if (open_ && (done_.back().feed != feed_mm_s || done_.back().corner_mode != corner_mode_ ||
                  done_.back().blend_tolerance != blend_tolerance_)) {
        close_run();  // one feed and one path control mode per subpath
    }
    if (!open_) {
        Subpath sp;
        sp.basis = is_line_piece(piece) ? PathBasis::kPolyline : PathBasis::kBezier;
        sp.closed = false;
        sp.feed = feed_mm_s;
        sp.location = at;
        sp.pause_before = pause_next_;
        sp.dwell_before = dwell_next_;
        sp.dwell_pen_down = dwell_pen_down_;
        sp.corner_mode = corner_mode_;
        sp.blend_tolerance = blend_tolerance_;
        pause_next_ = false;
        dwell_next_ = 0;
        dwell_pen_down_ = false;
        sp.points.push_back(point(p0));
        done_.push_back(std::move(sp));
        open_ = true;
    } else if (done_.back().points.back() != point(p0)) {
        throw std::logic_error("RunBuilder::draw: piece does not start where the run ends");
    }
    Subpath& run = done_.back();
    // One curve segment per piece, as a polyline and as a Bezier chain alike.
    run.segment_lines.push_back(static_cast<std::uint32_t>(at.line));
    if (run.basis == PathBasis::kPolyline && is_line_piece(piece)) {
        run.points.push_back(point(piece.p[3]));  // the planner makes the same cubic of it
        return;
    }
    if (run.basis == PathBasis::kPolyline) to_bezier_chain(run);
    for (std::size_t k = 1; k < piece.p.size(); ++k) run.points.push_back(point(piece.p[k]));
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
