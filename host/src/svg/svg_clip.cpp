// Cutting strokes at a clip region's boundary. The region's edges sit in a uniform grid over
// their bounding box so that a hatch of many lines against a finely flattened circle costs the
// edges each line passes near, not every pair of segment and edge.
#include "pathstream/host/svg_clip.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace pathstream::host::svg {
namespace {

double cross(Point u, Point v) {
    return u.x * v.y - u.y * v.x;
}
Point sub(Point u, Point v) {
    return {u.x - v.x, u.y - v.y};
}
Point lerp(Point a, Point b, double t) {
    return {a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t};
}

Point bezier(const Cubic& c, double t) {
    const double s = 1 - t;
    const double w0 = s * s * s, w1 = 3 * s * s * t, w2 = 3 * s * t * t, w3 = t * t * t;
    return {w0 * c[0].x + w1 * c[1].x + w2 * c[2].x + w3 * c[3].x,
            w0 * c[0].y + w1 * c[1].y + w2 * c[2].y + w3 * c[3].y};
}

// Cells per side at most: the prefix sums take (grid + 1)^2 words.
constexpr std::size_t kMaxGrid = 512;

}  // namespace

std::size_t ClipRegion::column(double x) const {
    const double c = std::floor((x - lo_.x) / cell_w_);
    return c <= 0 ? 0 : std::min(grid_ - 1, static_cast<std::size_t>(std::min(c, 1e9)));
}

std::size_t ClipRegion::row(double y) const {
    const double r = std::floor((y - lo_.y) / cell_h_);
    return r <= 0 ? 0 : std::min(grid_ - 1, static_cast<std::size_t>(std::min(r, 1e9)));
}

template <class F>
void ClipRegion::cells_of(Point a, Point b, F&& f) const {
    // Only the part within the bounding box can meet an edge (Liang-Barsky, a little padded).
    const double pad_x = cell_w_ * 1e-6, pad_y = cell_h_ * 1e-6;
    double t0 = 0, t1 = 1;
    const Point d = sub(b, a);
    const double p[4] = {-d.x, d.x, -d.y, d.y};
    const double q[4] = {a.x - (lo_.x - pad_x), (hi_.x + pad_x) - a.x, a.y - (lo_.y - pad_y),
                         (hi_.y + pad_y) - a.y};
    for (int k = 0; k < 4; ++k) {
        if (p[k] == 0) {
            if (q[k] < 0) return;
            continue;
        }
        const double r = q[k] / p[k];
        if (p[k] < 0)
            t0 = std::max(t0, r);
        else
            t1 = std::min(t1, r);
        if (t0 > t1) return;
    }
    const Point s = lerp(a, b, t0), e = lerp(a, b, t1);
    const double x0 = std::min(s.x, e.x), x1 = std::max(s.x, e.x);
    const std::size_t c0 = column(x0 - pad_x), c1 = column(x1 + pad_x);
    for (std::size_t c = c0; c <= c1; ++c) {
        // The segment's y range within this column.
        double ya = s.y, yb = e.y;
        if (c0 != c1 && e.x != s.x) {
            const double left = std::max(x0, lo_.x + static_cast<double>(c) * cell_w_);
            const double right = std::min(x1, lo_.x + static_cast<double>(c + 1) * cell_w_);
            ya = s.y + (left - s.x) * (e.y - s.y) / (e.x - s.x);
            yb = s.y + (right - s.x) * (e.y - s.y) / (e.x - s.x);
        }
        const std::size_t r0 = row(std::min(ya, yb) - pad_y), r1 = row(std::max(ya, yb) + pad_y);
        for (std::size_t r = r0; r <= r1; ++r) f(r * grid_ + c);
    }
}

ClipRegion::ClipRegion(std::vector<ClipShape> shapes) {
    bool first = true;
    for (std::size_t s = 0; s < shapes.size(); ++s) {
        rules_.push_back(shapes[s].rule);
        for (const Ring& ring : shapes[s].rings) {
            for (std::size_t i = 0; i < ring.size(); ++i) {
                const Point a = ring[i], b = ring[(i + 1) % ring.size()];
                if (a == b) continue;
                edges_.push_back({a, b, static_cast<std::uint32_t>(s)});
                for (const Point q : {a, b}) {
                    lo_ = first ? q : Point{std::min(lo_.x, q.x), std::min(lo_.y, q.y)};
                    hi_ = first ? q : Point{std::max(hi_.x, q.x), std::max(hi_.y, q.y)};
                    first = false;
                }
            }
        }
    }
    stamp_.assign(edges_.size(), 0);
    const std::size_t n = edges_.size();
    // A grid of about one edge a cell; coarser while long edges would fill too many cells.
    grid_ = std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(std::sqrt(n))), 1, kMaxGrid);
    for (;;) {
        cell_w_ = std::max((hi_.x - lo_.x) / static_cast<double>(grid_), 1e-12);
        cell_h_ = std::max((hi_.y - lo_.y) / static_cast<double>(grid_), 1e-12);
        std::size_t entries = 0;
        for (const Edge& e : edges_) cells_of(e.a, e.b, [&](std::size_t) { ++entries; });
        if (grid_ == 1 || entries <= 8 * n + 1024) break;
        grid_ /= 2;
    }
    const std::size_t cells = grid_ * grid_;
    cell_start_.assign(cells + 1, 0);
    for (const Edge& e : edges_) cells_of(e.a, e.b, [&](std::size_t k) { ++cell_start_[k + 1]; });
    for (std::size_t k = 0; k < cells; ++k) cell_start_[k + 1] += cell_start_[k];
    cell_edges_.resize(cell_start_[cells]);
    std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
    for (std::size_t i = 0; i < n; ++i) {
        cells_of(edges_[i].a, edges_[i].b,
                 [&](std::size_t k) { cell_edges_[fill[k]++] = static_cast<std::uint32_t>(i); });
    }
    const std::size_t side = grid_ + 1;
    occupied_.assign(side * side, 0);
    for (std::size_t r = 0; r < grid_; ++r) {
        for (std::size_t c = 0; c < grid_; ++c) {
            const std::size_t k = r * grid_ + c;
            occupied_[(r + 1) * side + c + 1] =
                (cell_start_[k + 1] > cell_start_[k] ? 1 : 0) + occupied_[r * side + c + 1] +
                occupied_[(r + 1) * side + c] - occupied_[r * side + c];
        }
    }
}

bool ClipRegion::box_outside(Point lo, Point hi) const {
    return edges_.empty() || hi.x < lo_.x || lo.x > hi_.x || hi.y < lo_.y || lo.y > hi_.y;
}

bool ClipRegion::box_clear(Point lo, Point hi) const {
    if (box_outside(lo, hi)) return true;
    const double pad_x = cell_w_ * 1e-6, pad_y = cell_h_ * 1e-6;
    const std::size_t c0 = column(lo.x - pad_x), c1 = column(hi.x + pad_x);
    const std::size_t r0 = row(lo.y - pad_y), r1 = row(hi.y + pad_y);
    const std::size_t side = grid_ + 1;
    ++work_;
    return occupied_[(r1 + 1) * side + c1 + 1] - occupied_[r0 * side + c1 + 1] -
               occupied_[(r1 + 1) * side + c0] + occupied_[r0 * side + c0] ==
           0;
}

void ClipRegion::crossings(Point a, Point b, std::vector<Crossing>& out) const {
    out.clear();
    if (++query_ == 0) std::fill(stamp_.begin(), stamp_.end(), 0), query_ = 1;
    const Point d = sub(b, a);
    cells_of(a, b, [&](std::size_t k) {
        ++work_;
        for (std::uint32_t i = cell_start_[k]; i < cell_start_[k + 1]; ++i) {
            const std::uint32_t j = cell_edges_[i];
            if (stamp_[j] == query_) continue;
            stamp_[j] = query_;
            ++work_;
            const Edge& e = edges_[j];
            if ((cross(d, sub(e.a, a)) > 0) == (cross(d, sub(e.b, a)) > 0)) continue;
            const Point f = sub(e.b, e.a);
            if ((cross(f, sub(a, e.a)) > 0) == (cross(f, sub(b, e.a)) > 0)) continue;
            const double denom = cross(d, f);
            const double t = denom == 0 ? 0.5 : std::clamp(cross(sub(e.a, a), f) / denom, 0.0, 1.0);
            out.push_back({t, e.shape, denom < 0 ? 1 : -1});
        }
    });
    std::sort(out.begin(), out.end(),
              [](const Crossing& x, const Crossing& y) { return x.t < y.t; });
}

Point ClipRegion::outside_from(Point p, Point direction) const {
    const double size = std::hypot(direction.x, direction.y);
    const double reach = std::hypot(hi_.x - lo_.x, hi_.y - lo_.y) +
                         std::hypot(p.x - (lo_.x + hi_.x) / 2, p.y - (lo_.y + hi_.y) / 2) + 1;
    return {p.x - direction.x / size * reach, p.y - direction.y / size * reach};
}

bool ClipRegion::contains(Point p) const {
    if (box_outside(p, p)) return false;
    std::vector<Crossing> hits;
    crossings(outside_from(p, {1, 0}), p, hits);
    std::vector<int> winding(rules_.size(), 0);
    for (const Crossing& c : hits) winding[c.shape] += c.delta;
    for (const Crossing& c : hits) {
        if (inside(c.shape, winding[c.shape])) return true;
    }
    return false;
}

std::size_t flatten_count(const Cubic& c, double tolerance) {
    if (is_straight(c)) return 1;
    // |B''| <= 6 M, and a chord over a parameter step h deviates at most |B''| h^2 / 8.
    const double m =
        std::max(std::hypot(c[0].x - 2 * c[1].x + c[2].x, c[0].y - 2 * c[1].y + c[2].y),
                 std::hypot(c[1].x - 2 * c[2].x + c[3].x, c[1].y - 2 * c[2].y + c[3].y));
    const double n = std::ceil(std::sqrt(0.75 * m / tolerance));
    return n < 1 ? 1 : n > 1e15 ? static_cast<std::size_t>(1e15) : static_cast<std::size_t>(n);
}

bool is_straight(const Cubic& c) {
    const Cubic line = line_cubic(c[0], c[3]);
    const double size = std::max(1.0, std::hypot(c[3].x - c[0].x, c[3].y - c[0].y));
    return std::hypot(c[1].x - line[1].x, c[1].y - line[1].y) <= 1e-9 * size &&
           std::hypot(c[2].x - line[2].x, c[2].y - line[2].y) <= 1e-9 * size;
}

namespace {

// The winding number of every shape at the current point of a walk along a chain, and how
// many shapes have the point inside.
class Walk {
public:
    explicit Walk(const ClipRegion& region) : region_(region), winding_(region.shapes(), 0) {}

    bool started() const { return started_; }
    bool inside() const { return inside_count_ > 0; }

    // Starts at `a`, heading for `b`: the windings at `a`, walked from outside on that line
    // so that they agree with the crossings of the segment a-b.
    void start(Point a, Point b) {
        started_ = true;
        Point d = sub(b, a);
        if (d.x == 0 && d.y == 0) d = {1, 0};
        region_.crossings(region_.outside_from(a, d), a, hits_);
        for (const auto& c : hits_) step(c);
    }

    // Walks the segment a-b: the parameter intervals inside, in order.
    std::vector<std::pair<double, double>> walk(Point a, Point b) {
        std::vector<std::pair<double, double>> out;
        region_.crossings(a, b, hits_);
        double from = 0;
        for (const auto& c : hits_) {
            const bool was = inside();
            step(c);
            if (was && !inside() && c.t > from) out.emplace_back(from, c.t);
            if (!was && inside()) from = c.t;
        }
        if (inside() && from < 1) out.emplace_back(from, 1.0);
        return out;
    }

private:
    void step(const ClipRegion::Crossing& c) {
        int& w = winding_[c.shape];
        const bool before = region_.inside(c.shape, w);
        w += c.delta;
        inside_count_ += static_cast<int>(region_.inside(c.shape, w)) - static_cast<int>(before);
    }

    const ClipRegion& region_;
    std::vector<int> winding_;
    int inside_count_ = 0;
    bool started_ = false;
    std::vector<ClipRegion::Crossing> hits_;
};

}  // namespace

CubicSubpaths clip_chain(const std::vector<Cubic>& chain, const ClipRegion& region,
                         double tolerance, std::uint64_t& work, std::uint64_t max_work) {
    CubicSubpaths out;
    bool open = false;  // the last part ended inside: the next one continues its run
    const auto append = [&](const Cubic& c, bool continues) {
        if (!(open && continues)) out.emplace_back();
        out.back().push_back(c);
    };
    const auto charge = [&](std::uint64_t steps) {
        work += steps;
        if (work > max_work) {
            throw ValueError("clipping needs more than " + std::to_string(max_work) +
                             " steps (the reader's limit)");
        }
    };
    Walk walk(region);
    for (const Cubic& c : chain) {
        Point lo = c[0], hi = c[0];
        for (const Point& q : c) {
            lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
            hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
        }
        // No edge near the piece's control hull: no crossing, the windings stay.
        if (region.box_outside(lo, hi)) {
            open = false;
            continue;
        }
        std::uint64_t before = region.work();
        if (walk.started() && region.box_clear(lo, hi)) {
            charge(region.work() - before);
            if (walk.inside()) append(c, true);
            open = walk.inside();
            continue;
        }
        const std::size_t n = flatten_count(c, tolerance);
        charge(n);
        before = region.work();
        if (!walk.started()) walk.start(c[0], n == 1 ? c[3] : bezier(c, 1.0 / n));
        bool whole = true;
        Point a = c[0];
        // Parts of this piece: from, to, starting at its segment's start, ending at its end.
        struct Part {
            Point from, to;
            bool starts, ends;
        };
        std::vector<Part> parts;
        bool gap = false;  // a segment with nothing inside ends the run
        for (std::size_t k = 1; k <= n; ++k) {
            const Point b = k == n ? c[3] : bezier(c, static_cast<double>(k) / n);
            const auto intervals = walk.walk(a, b);
            whole = whole && intervals.size() == 1 && intervals[0].first == 0 &&
                    intervals[0].second == 1;
            if (intervals.empty() && !gap) {
                gap = true;
                parts.push_back({b, b, false, false});  // marks the end of a run
            }
            for (const auto& [t0, t1] : intervals) {
                parts.push_back(
                    {t0 == 0 ? a : lerp(a, b, t0), t1 == 1 ? b : lerp(a, b, t1), t0 == 0, t1 == 1});
                gap = false;
            }
            a = b;
            if (k % 1024 == 0) charge(region.work() - before), before = region.work();
        }
        charge(region.work() - before);
        if (whole) {
            append(c, true);
            open = true;
            continue;
        }
        for (const Part& part : parts) {
            if (!(part.from == part.to && !part.starts && !part.ends))
                append(line_cubic(part.from, part.to), part.starts);
            open = part.ends;
        }
    }
    return out;
}

}  // namespace pathstream::host::svg
