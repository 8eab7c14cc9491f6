// The curves a wireframe has drawn, by their model control points, so that a seam two patches
// share (or any curve given twice) is drawn once.
#pragma once

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "pathstream/host/surface.hpp"

namespace pathstream::host::surface {

class SeamSet {
public:
    /// `resolution`: model distance below which control points count as equal (> 0).
    explicit SeamSet(double resolution) : resolution_(resolution) {}

    /// True when a curve with these cubic control points (either direction) was added already;
    /// else adds it and returns false. O(log n) plus the candidates sharing its end cells.
    bool seen_or_add(const std::vector<Point3>& cubic);

private:
    using Cell = std::array<std::int64_t, 3>;
    Cell cell(const Point3& p) const;
    bool same(const std::vector<Point3>& a, const std::vector<Point3>& b, bool reversed) const;

    double resolution_;
    std::map<std::pair<Cell, Cell>, std::vector<std::vector<Point3>>> by_ends_;
};

/// True when every point of `q` is within `resolution` of the first (a curve that is a point).
bool is_point(const std::vector<Point3>& q, double resolution);

}  // namespace pathstream::host::surface
