// Seams found by the cells of a curve's two ends: equal curves share them, whatever the
// direction, so only a handful of candidates is ever compared in full.
#include "seam_set.hpp"

#include <cmath>

namespace pathstream::host::surface {

SeamSet::Cell SeamSet::cell(const Point3& p) const {
    // Cells twice the resolution wide: two points within it differ by at most one cell.
    const double w = 2 * resolution_;
    return {static_cast<std::int64_t>(std::llround(p[0] / w)),
            static_cast<std::int64_t>(std::llround(p[1] / w)),
            static_cast<std::int64_t>(std::llround(p[2] / w))};
}

bool SeamSet::same(const std::vector<Point3>& a, const std::vector<Point3>& b,
                   bool reversed) const {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const Point3& q = reversed ? b[b.size() - 1 - i] : b[i];
        for (int k = 0; k < 3; ++k) {
            if (std::abs(a[i][k] - q[k]) > resolution_) return false;
        }
    }
    return true;
}

bool SeamSet::seen_or_add(const std::vector<Point3>& cubic) {
    Cell a = cell(cubic.front()), b = cell(cubic.back());
    if (b < a) std::swap(a, b);
    // Points on either side of a cell boundary land in neighbouring cells; looking in the
    // key's own cells finds equal curves whose ends round alike, which exact seams do.
    auto& bucket = by_ends_[{a, b}];
    for (const auto& other : bucket) {
        if (same(cubic, other, false) || same(cubic, other, true)) return true;
    }
    bucket.push_back(cubic);
    return false;
}

bool is_point(const std::vector<Point3>& q, double resolution) {
    for (const Point3& p : q) {
        for (int k = 0; k < 3; ++k) {
            if (std::abs(p[k] - q[0][k]) > resolution) return false;
        }
    }
    return true;
}

}  // namespace pathstream::host::surface
