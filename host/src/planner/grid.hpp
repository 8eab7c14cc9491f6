// The lookahead grid of a path (or of one window of it): nodes at known arc length along every
// segment, the pieces between stops and the runs between pen changes, and the lookup of a
// point by arc length (grid.cpp). Every later stage reads it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "cubic.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// Per-node vectors stored flat, `axes` doubles each (a Vec per node would be 64 bytes).
class VecArray {
public:
    struct ConstRow {
        const double* p;
        std::size_t n;
        double operator[](std::size_t i) const { return i < n ? p[i] : 0.0; }
        operator Vec() const {
            Vec v{};
            for (std::size_t i = 0; i < n; ++i) v[i] = p[i];
            return v;
        }
    };
    struct Row {
        double* p;
        std::size_t n;
        double& operator[](std::size_t i) const { return p[i]; }
        operator Vec() const { return ConstRow{p, n}; }
        const Row& operator=(const Vec& v) const {
            for (std::size_t i = 0; i < n; ++i) p[i] = v[i];
            return *this;
        }
        const Row& operator=(const Row& o) const { return *this = Vec(o); }
    };

    void set_axes(std::size_t axes) { axes_ = axes; }
    void reserve(std::size_t n) { data_.reserve(n * axes_); }
    void push_back(const Vec& v) {
        data_.insert(data_.end(), v.begin(), v.begin() + static_cast<std::ptrdiff_t>(axes_));
    }
    std::size_t size() const { return axes_ == 0 ? 0 : data_.size() / axes_; }
    ConstRow operator[](std::size_t k) const { return {data_.data() + k * axes_, axes_}; }
    Row operator[](std::size_t k) { return {data_.data() + k * axes_, axes_}; }

private:
    std::size_t axes_ = 0;
    std::vector<double> data_;
};

/// The lookahead grid of the whole path: nodes along every non-degenerate segment at
/// increasing arc length `lambda` (mm from the start of the path). Where two segments meet
/// there are two nodes at the same lambda (end of one, start of the next).
struct Grid {
    std::size_t axes = 0;
    std::vector<double> lambda, u;
    std::vector<std::uint32_t> seg;
    VecArray q, tangent, curvature;  ///< point, unit tangent dq/dl, curvature d2q/dl2
    std::vector<double> feed;        ///< requested speed along the path at the node
    VecArray corner_jump;            ///< tangent jump at a crossed corner (0 elsewhere)
    // Per node, derived once the grid is complete (finish_grid), for the forward pass's loops.
    std::vector<double> param_pace;      ///< du/dlambda = 1 / |dq/du| at the node (0 where q' = 0)
    std::vector<double> curvature_norm;  ///< |curvature|
    std::vector<std::uint8_t> corner;    ///< 1 where corner_jump is not 0

    std::size_t size() const { return lambda.size(); }
};

/// A stretch of the path between two stops: nodes first..last of the grid, started and ended
/// at rest. A piece of zero length has first == last.
struct Piece {
    std::size_t first = 0, last = 0;
    std::size_t run = 0;
    double feed = 0;  ///< requested speed along it (mm/s)
};

/// Consecutive segments with the same pen state and subpath: drawn (or travelled) without a
/// pen change. Holds its pieces in order.
struct Run {
    bool pen_down = true;
    std::size_t subpath = 0;
    std::size_t first_segment = 0, last_segment = 0;
    bool pause_before = false;  ///< the first segment's pause and rest (BezierSegment)
    double dwell_before = 0;
    bool dwell_pen_down = false;
    std::uint8_t outputs = 0, pause_outputs = 0;  ///< the first segment's (BezierSegment)
    std::vector<std::size_t> pieces;
    Vec start{}, end{};  ///< mm
};

struct PathGrid {
    Grid grid;
    std::vector<Cubic> cubics;
    std::vector<double> cubic_size;  ///< Cubic::size() of each
    std::vector<Piece> pieces;
    std::vector<Run> runs;
    double pen_down_length = 0, travel_length = 0;
};

/// Builds the grid, the stops (sharp corners, cusps, pen changes, ends) and the runs.
/// `profile` gives the feeds. Throws PlanError on unusable input.
/// `first_index`: the global index of segments[0], for messages (a window of a streamed job).
PathGrid build_grid(const std::vector<BezierSegment>& segments, const MachineProfile& profile,
                    const PlanOptions& options, std::size_t first_index = 0);

/// Point and unit tangent at arc length `lambda` inside `piece`. `hint` is a node index to
/// start searching from (updated), for the monotone walk of the forward pass.
struct PathAt {
    Vec q{}, t{};
};
/// `precise` = false skips the arc length's refinement: the point is exactly on the path but
/// its arc length may be off by about 1e-6 of the grid interval (enough for a distance measured
/// across the path; four times cheaper).
PathAt path_at(const PathGrid& g, const Piece& piece, double lambda, std::size_t& hint,
               bool precise = true);

}  // namespace pathstream::host::planner_detail
