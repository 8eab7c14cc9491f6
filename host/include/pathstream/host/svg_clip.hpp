// Clipping of the SVG reader's strokes by a clip region (clip-path, nested viewports): the
// strokes are cut where they cross the region's boundary (docs/formats-svg.md, "Clipping").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {

/// How the rings of one clip shape decide what is inside (SVG's clip-rule).
enum class FillRule { kNonZero, kEvenOdd };

/// A closed polygon: the last point joins the first.
using Ring = std::vector<Point>;

/// One shape of a clip path (one child of a <clipPath>), flattened into rings.
struct ClipShape {
    std::vector<Ring> rings;
    FillRule rule = FillRule::kNonZero;
};

/// The union of clip shapes, indexed on a grid so that cutting a segment and testing a point
/// cost the edges near them, not every edge of the region.
class ClipRegion {
public:
    /// Indexes `shapes`. Memory is O(total ring points).
    explicit ClipRegion(std::vector<ClipShape> shapes);

    /// Where the segment a-b crosses an edge: its parameter t in [0, 1] along a + t (b - a),
    /// the edge's shape and the change of that shape's winding number.
    struct Crossing {
        double t;
        std::uint32_t shape;
        int delta;
    };

    /// The crossings of the segment a-b, by ascending t. An edge counts when its ends lie on
    /// different sides of the segment's line and the segment's ends on different sides of
    /// the edge's line, each side test half-open; since the test of a shared end point is the
    /// same computation, a chain of segments crosses the boundary consistently (a crossing
    /// at a vertex or at a joint counts once).
    void crossings(Point a, Point b, std::vector<Crossing>& out) const;

    /// A point far outside the region on the line through `p` against `direction` (nonzero),
    /// where every winding number is 0: walks start there.
    Point outside_from(Point p, Point direction) const;

    /// Shapes, for sizing winding tallies.
    std::size_t shapes() const { return rules_.size(); }
    /// True when winding number `w` of shape `s` is inside by its rule.
    bool inside(std::uint32_t s, int w) const {
        return rules_[s] == FillRule::kNonZero ? w != 0 : w % 2 != 0;
    }

    /// True when `p` is inside some shape by that shape's rule (a point on the boundary may go
    /// either way). Walks from outside_from(p, (1, 0)).
    bool contains(Point p) const;

    /// True when no edge of the region comes near the box [lo, hi] (so the box lies wholly
    /// inside or wholly outside). Conservative: false may be returned for a clear box.
    bool box_clear(Point lo, Point hi) const;

    /// True when the box [lo, hi] misses the region's bounding box.
    bool box_outside(Point lo, Point hi) const;

    /// Edge tests and grid cells visited so far: what the queries cost.
    std::uint64_t work() const { return work_; }

private:
    struct Edge {
        Point a, b;
        std::uint32_t shape;
    };
    // Calls f(cell) for every grid cell the segment a-b may pass through (a superset).
    template <class F>
    void cells_of(Point a, Point b, F&& f) const;
    std::size_t column(double x) const;
    std::size_t row(double y) const;

    std::vector<FillRule> rules_;  // per shape
    std::vector<Edge> edges_;
    Point lo_{}, hi_{};     // bounding box of every edge
    std::size_t grid_ = 1;  // cells per side
    double cell_w_ = 1, cell_h_ = 1;
    std::vector<std::uint32_t> cell_start_;  // CSR: edges of cell k at [start[k], start[k + 1])
    std::vector<std::uint32_t> cell_edges_;
    std::vector<std::uint32_t> occupied_;       // (grid + 1)^2 prefix sums of non-empty cells
    mutable std::vector<std::uint32_t> stamp_;  // per edge: the query that last tested it
    mutable std::uint32_t query_ = 0;
    mutable std::uint64_t work_ = 0;
};

/// Segments that approximate the cubic `c` within `tolerance` (chords of equal parameter
/// steps, from the bound on the second derivative); 1 for a straight piece.
std::size_t flatten_count(const Cubic& c, double tolerance);

/// True when `c`'s control points lie at the thirds of its chord (within 1e-9 of its size):
/// a straight piece as the reader writes lines.
bool is_straight(const Cubic& c);

/// Cuts one connected chain of pieces (in mm) at the boundary of `region`. Pieces wholly
/// inside are kept as they are; a piece that crosses the boundary is flattened within
/// `tolerance` and its inside parts become straight pieces. Each run of inside parts is one
/// subpath of the result. `segments` counts the flattened segments tested (the caller's
/// budget); more than `max_segments` in all throws ValueError.
CubicSubpaths clip_chain(const std::vector<Cubic>& chain, const ClipRegion& region,
                         double tolerance, std::uint64_t& segments, std::uint64_t max_segments);

}  // namespace pathstream::host::svg
