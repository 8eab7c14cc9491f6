// Distance from a point to the pen-down path, for the deviation of the per-tick check
// (projection.cpp).
#pragma once

#include <cstddef>
#include <vector>

#include "cubic.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// Distance from points to a set of Bezier segments (the pen-down path), for the plan check.
/// Queries are expected to move along the path: each one first searches the segments around
/// the previous answer (both ways, a window that grows with the step; closed runs wrap), then,
/// only if that finds nothing within `global_below` mm, every segment (pruned by control-point
/// boxes), so that a distance above `global_below` is always the true one. Each candidate
/// segment: branch and bound over de Casteljau halves (a half is dropped when the box of its
/// control points is farther than the best distance so far), pieces flat to 1 um projected on
/// their chord and refined by Newton on (q(u) - p) . q'(u) = 0: the global nearest point, exact
/// to rounding.
class PathProjector {
public:
    PathProjector(std::vector<Cubic> segments, std::vector<std::size_t> index, double global_below);
    /// Distance (mm) from p to the nearest segment; `segment` gets its index (as given).
    double distance(const Vec& p, std::size_t& segment);
    /// An upper bound of distance(p), in a few Newton steps: the distance to the point of the
    /// path the cursor follows (from the last answer, onto the joined segment after or before
    /// when it runs off an end). Moves the cursor there. Infinity before the first distance().
    /// A caller after the largest distance needs distance() only where this bound passes it.
    double follow(const Vec& p);
    bool empty() const { return segs_.empty(); }

    /// Where the search stands: the segment of the last answer (as indexed) and its parameter,
    /// the point asked and its distance.
    struct Cursor {
        std::size_t segment = 0;
        double u = 0;
        Vec p{};
        double d = 0;
        bool started = false;
    };
    Cursor cursor() const;
    /// Continues from another projector's cursor (over an overlapping set of segments): when
    /// its segment is here, the next search starts there; else as if nothing was asked yet.
    void resume(const Cursor& c);

private:
    /// Distance from p to segment i when it is below `bound` (mm), else a value >= bound;
    /// `at` (optional) gets the parameter of the nearest point when one below bound is found.
    double segment_distance(std::size_t i, const Vec& p, double bound, double* at = nullptr) const;
    double box_distance(std::size_t i, const Vec& p) const;
    /// Builds the bounding-box tree over segments order_[first, last) and returns its node.
    std::size_t build_tree(std::size_t first, std::size_t last);
    /// Every segment whose box is nearer than `best` goes to `consider` (which lowers best):
    /// the tree's boxes are pruned against the best distance so far, O(log n) for a point near
    /// the path instead of a scan of every segment.
    template <typename Consider>
    void search_tree(const Vec& p, double& best, Consider&& consider) const;

    /// A node of the bounding-box tree: a leaf holds order_[first, last), an inner node its
    /// two children.
    struct TreeNode {
        Vec lo{}, hi{};
        std::size_t first = 0, last = 0;
        std::size_t left = 0, right = 0;  ///< children (both 0 for a leaf)
    };
    std::vector<TreeNode> tree_;
    std::vector<std::size_t> order_;

    std::vector<Cubic> segs_;
    std::vector<std::size_t> index_;
    std::vector<double> length_;
    std::vector<Vec> lo_, hi_;
    std::vector<std::size_t> run_first_, run_last_;
    double global_below_;
    std::size_t cursor_ = 0;
    Vec last_p_{};
    double last_d_ = 0;
    double last_u_ = 0;  ///< parameter of the last answer on segment cursor_
    bool started_ = false;
};

}  // namespace pathstream::host::planner_detail
