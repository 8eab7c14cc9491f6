// Subpath order: joining touching ends, nearest neighbour with a grid, 2-opt and Or-opt.
#include "pathstream/host/path_order.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace pathstream::host {
namespace {

/// Euclidean distance over every axis.
double distance(PointRef a, PointRef b) {
    double s = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) s += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(s);
}

/// Whether the basis joins exactly by concatenating point lists (see merge_touching).
bool joinable_basis(PathBasis basis) {
    return basis == PathBasis::kPolyline || basis == PathBasis::kBezier;
}

/// An open polyline or Bezier chain whose ends meet: it may start at any on-curve vertex
/// (unless it rests at some of its vertices: those would move).
bool is_open_loop(const Subpath& s, double tolerance) {
    if (s.closed || !joinable_basis(s.basis) || tolerance < 0 ||
        s.corner_mode == CornerMode::kExactStop)
        return false;
    const std::size_t m = s.points.size();
    if (s.basis == PathBasis::kBezier ? m < 7 || (m - 1) % 3 != 0 : m < 3) return false;
    return distance(s.points.front(), s.points.back()) <= tolerance;
}

/// An open loop started at its vertex `shift`: Q[shift..m-1] then Q[1..shift]. Q[m-1] stands
/// in for Q[0] (they are within the tolerance), so the drawn curve moves by at most that much.
Subpath rotated_open_loop(const Subpath& s, std::size_t shift) {
    if (shift == 0) return s;
    Subpath r = s;
    r.points.clear();
    r.segment_lines.clear();
    r.points.append(s.points, shift, s.points.size());
    r.points.append(s.points, 1, shift + 1);
    return r;
}

/// rotated_open_loop in place: the same points, none copied but Q[shift] once.
void rotate_open_loop(Subpath& s, std::size_t shift) {
    if (shift == 0) return;
    s.segment_lines.clear();
    s.points.erase_front(1);  // Q[1..m-1]
    s.points.rotate(shift - 1);
    s.points.push_back(s.points.front());  // Q[shift..m-1], Q[1..shift]
}

/// Subpath::stops after the segments were renumbered: joint k becomes (k * sign + shift) mod n,
/// kept ascending; a joint landing on the ends (0) is dropped (the motion rests there anyway).
void renumber_stops(Subpath& r, long long sign, long long shift) {
    if (r.stops.empty()) return;
    const long long n = static_cast<long long>(chain_segments(r));
    std::vector<std::uint32_t> out;
    out.reserve(r.stops.size());
    for (const std::uint32_t k : r.stops) {
        const long long j = n > 0 ? ((sign * static_cast<long long>(k) + shift) % n + n) % n : 0;
        if (j > 0) out.push_back(static_cast<std::uint32_t>(j));
    }
    std::sort(out.begin(), out.end());
    r.stops = std::move(out);
}

/// reversed_subpath in place.
void reverse_points(Subpath& r) {
    r.points.reverse(r.closed ? 1 : 0);
    renumber_stops(r, -1, static_cast<long long>(chain_segments(r)));
    std::reverse(r.segment_lines.begin(), r.segment_lines.end());  // segment k is now n - 1 - k
}

/// rotated_subpath in place (its checks and messages).
void rotate_points(Subpath& r, std::size_t shift) {
    if (!r.closed) throw std::invalid_argument("rotated_subpath: the subpath is open");
    if (r.points.empty()) return;
    if (r.basis == PathBasis::kBezier && shift % 3 != 0) {
        throw std::invalid_argument(
            "rotated_subpath: a Bezier chain starts only at on-curve points (shift " +
            std::to_string(shift) + " is not a multiple of 3)");
    }
    r.segment_lines.clear();
    r.points.rotate(shift);
    renumber_stops(r, 1,
                   -static_cast<long long>(r.basis == PathBasis::kBezier ? shift / 3 : shift));
}

/// 2-D cell of a point for the grids: the first two axes (one-axis paths: y = 0).
std::pair<double, double> plane(PointRef p) {
    return {p.empty() ? 0.0 : p[0], p.size() > 1 ? p[1] : 0.0};
}

/// One thing to draw: an open subpath (two directions) or a loop (any of its start vertices).
struct Item {
    std::size_t subpath = 0;
    bool cyclic = false;              ///< closed, or an open loop
    PointList starts;                 ///< cyclic: curve point at each allowed start
    std::vector<std::size_t> shifts;  ///< cyclic: rotation giving that start
    PathPoint first, last;            ///< open: curve ends
};

/// A place in the order: the item, and its direction (open) or start (cyclic).
struct Visit {
    std::size_t item = 0;
    std::size_t choice = 0;  ///< open: 0 forward, 1 reversed; cyclic: index into starts
};

std::vector<Item> make_items(const Path& path, double tolerance) {
    std::vector<Item> items;
    for (std::size_t i = 0; i < path.subpaths.size(); ++i) {
        const Subpath& s = path.subpaths[i];
        Item it;
        it.subpath = i;
        const std::size_t m = s.points.size();
        if (s.closed && m >= 3) {
            it.cyclic = true;
            const std::size_t step = s.basis == PathBasis::kBezier ? 3 : 1;
            for (std::size_t r = 0; r + step <= m; r += step) {
                if (s.basis == PathBasis::kBSpline) {
                    PathPoint p(s.points[r].size());
                    const PointRef a = s.points[(r + m - 1) % m], b = s.points[r],
                                   c = s.points[(r + 1) % m];
                    for (std::size_t k = 0; k < p.size(); ++k) p[k] = (a[k] + 4 * b[k] + c[k]) / 6;
                    it.starts.push_back(p);
                } else {
                    it.starts.push_back(s.points[r]);
                }
                it.shifts.push_back(r);
            }
        } else if (is_open_loop(s, tolerance)) {
            it.cyclic = true;
            const std::size_t step = s.basis == PathBasis::kBezier ? 3 : 1;
            for (std::size_t r = 0; r + 1 < m; r += step) {
                it.starts.push_back(s.points[r]);
                it.shifts.push_back(r);
            }
        } else if (m > 0) {
            it.first = curve_start(s);
            it.last = curve_end(s);
        }
        items.push_back(std::move(it));
    }
    return items;
}

/// The order being improved: visits, their end points, and the work counter.
class Tour {
public:
    Tour(const std::vector<Item>& items, PathPoint start, std::size_t work_limit)
        : items_(items), start_(std::move(start)), limit_(work_limit) {}

    std::vector<Visit> visits;

    PointRef start_of(const Visit& v) const {
        const Item& it = items_[v.item];
        return it.cyclic ? it.starts[v.choice] : PointRef(v.choice == 0 ? it.first : it.last);
    }
    PointRef end_of(const Visit& v) const {
        const Item& it = items_[v.item];
        return it.cyclic ? it.starts[v.choice] : PointRef(v.choice == 0 ? it.last : it.first);
    }
    /// Where the pen is before position k.
    PointRef before(std::size_t k) const {
        return k == 0 ? PointRef(start_) : end_of(visits[k - 1]);
    }

    double travel() const {
        double t = 0;
        for (std::size_t k = 0; k < visits.size(); ++k)
            t += distance(before(k), start_of(visits[k]));
        return t;
    }
    bool spent() const { return work_ >= limit_; }
    std::size_t work() const { return work_; }

    /// Reverses positions i..j (each open visit flips): first improvement, windowed.
    bool two_opt(std::size_t window) {
        bool improved = false;
        const std::size_t n = visits.size();
        for (std::size_t i = 0; i < n && !spent(); ++i) {
            for (std::size_t j = i; j < n && j <= i + window; ++j) {
                ++work_;
                const PointRef a = before(i);
                double old_cost = distance(a, start_of(visits[i]));
                double new_cost = distance(a, end_of(visits[j]));
                if (j + 1 < n) {
                    const PointRef b = start_of(visits[j + 1]);
                    old_cost += distance(end_of(visits[j]), b);
                    new_cost += distance(start_of(visits[i]), b);
                }
                if (new_cost < old_cost - kGain) {
                    std::reverse(visits.begin() + static_cast<std::ptrdiff_t>(i),
                                 visits.begin() + static_cast<std::ptrdiff_t>(j) + 1);
                    for (std::size_t k = i; k <= j; ++k) {
                        if (!items_[visits[k].item].cyclic) visits[k].choice ^= 1;
                    }
                    improved = true;
                }
            }
        }
        return improved;
    }

    /// Moves a block of 1..3 visits (maybe reversed) to another gap within the window.
    bool or_opt(std::size_t window) {
        bool improved = false;
        for (std::size_t len = 1; len <= 3; ++len) {
            for (std::size_t i = 0; i + len <= visits.size() && !spent(); ++i) {
                if (try_move_block(i, len, window)) improved = true;
            }
        }
        return improved;
    }

    /// Each loop's start vertex: the one closest to its neighbours in the order.
    bool refine_starts() {
        bool improved = false;
        for (std::size_t k = 0; k < visits.size() && !spent(); ++k) {
            const Item& it = items_[visits[k].item];
            if (!it.cyclic) continue;
            const PointRef a = before(k);
            const bool has_b = k + 1 < visits.size();
            const PointRef b = has_b ? start_of(visits[k + 1]) : a;
            const auto cost = [&](std::size_t c) {
                return distance(a, it.starts[c]) + (has_b ? distance(it.starts[c], b) : 0.0);
            };
            std::size_t best = visits[k].choice;
            double best_cost = cost(best);
            for (std::size_t c = 0; c < it.starts.size(); ++c) {
                ++work_;
                const double value = cost(c);
                if (value < best_cost - kGain) best = c, best_cost = value;
            }
            if (best != visits[k].choice) visits[k].choice = best, improved = true;
        }
        return improved;
    }

private:
    static constexpr double kGain = 1e-9;  // mm: smaller gains are rounding, not progress

    bool try_move_block(std::size_t i, std::size_t len, std::size_t window) {
        const std::size_t n = visits.size();
        const std::size_t j = i + len - 1;
        const PointRef a = before(i);
        const bool has_b = j + 1 < n;
        const PointRef b = has_b ? start_of(visits[j + 1]) : a;
        const PointRef s = start_of(visits[i]);
        const PointRef e = end_of(visits[j]);
        // Taking the block out saves this much (a then straight to b).
        const double removed = distance(a, s) + (has_b ? distance(e, b) - distance(a, b) : 0.0);
        const std::size_t lo = i > window ? i - window : 0, hi = std::min(n, j + 1 + window);
        for (std::size_t p = lo; p <= hi; ++p) {  // gap before position p (p == n: the end)
            if (p >= i && p <= j + 1) continue;
            ++work_;
            const PointRef c = before(p);
            const bool has_d = p < n;
            const PointRef d = has_d ? start_of(visits[p]) : c;
            const double base = has_d ? distance(c, d) : 0.0;
            const double forward = distance(c, s) + (has_d ? distance(e, d) : 0.0) - base;
            const double backward = distance(c, e) + (has_d ? distance(s, d) : 0.0) - base;
            const bool flip = backward < forward;
            if (std::min(forward, backward) < removed - kGain) {
                std::vector<Visit> block(visits.begin() + static_cast<std::ptrdiff_t>(i),
                                         visits.begin() + static_cast<std::ptrdiff_t>(j) + 1);
                if (flip) {
                    std::reverse(block.begin(), block.end());
                    for (Visit& v : block) {
                        if (!items_[v.item].cyclic) v.choice ^= 1;
                    }
                }
                visits.erase(visits.begin() + static_cast<std::ptrdiff_t>(i),
                             visits.begin() + static_cast<std::ptrdiff_t>(j) + 1);
                const std::size_t at = p > j ? p - len : p;
                visits.insert(visits.begin() + static_cast<std::ptrdiff_t>(at), block.begin(),
                              block.end());
                return true;
            }
        }
        return false;
    }

    const std::vector<Item>& items_;
    PathPoint start_;
    std::size_t limit_;
    std::size_t work_ = 0;
};

/// A uniform 2-D grid of candidate starts for the nearest-neighbour search; rebuilt smaller as
/// starts are taken so that a query never scans a mostly empty grid.
class StartGrid {
public:
    struct Entry {
        PointRef point;  ///< into the items the grid is built from
        std::size_t item, choice;
    };

    explicit StartGrid(std::vector<Entry> entries) : entries_(std::move(entries)) {
        alive_.assign(entries_.size(), true);
        live_ = entries_.size();
        rebuild();
    }

    /// Removes the given entries (every start of one item).
    void remove_item(const std::vector<std::size_t>& entry_ids) {
        for (std::size_t id : entry_ids) {
            if (!alive_[id]) continue;
            alive_[id] = false;
            --live_;
            auto& cell = cells_[cell_of_entry_[id]];
            cell.erase(std::find(cell.begin(), cell.end(), id));
        }
        if (live_ > 0 && live_ * 4 < built_size_) rebuild();
    }

    /// The live entry nearest to p (ties: the lowest id); entries_.size() when none is left.
    std::size_t nearest(PointRef p) const {
        if (live_ == 0) return entries_.size();
        const auto [x, y] = plane(p);
        // Distances to the projection of p onto the grid bound those to p from below.
        const long cx = cell_index(x, x0_, w_), cy = cell_index(y, y0_, h_);
        std::size_t best = entries_.size();
        double best_d = std::numeric_limits<double>::infinity();
        const double step = std::min(w_, h_);
        const long g = static_cast<long>(g_);
        const auto visit = [&](long gx, long gy) {
            if (gx < 0 || gx >= g || gy < 0 || gy >= g) return;
            for (std::size_t id : cells_[static_cast<std::size_t>(gx * g + gy)]) {
                const double d = distance(p, entries_[id].point);
                if (d < best_d || (d == best_d && id < best)) best = id, best_d = d;
            }
        };
        for (long r = 0; r <= g; ++r) {
            for (long gx = cx - r; gx <= cx + r; ++gx) {
                if (gx == cx - r || gx == cx + r) {
                    for (long gy = cy - r; gy <= cy + r; ++gy) visit(gx, gy);
                } else {
                    visit(gx, cy - r);
                    visit(gx, cy + r);
                }
            }
            if (best < entries_.size() && best_d <= static_cast<double>(r) * step) break;
        }
        return best;
    }

    const Entry& entry(std::size_t id) const { return entries_[id]; }
    std::size_t size() const { return entries_.size(); }

private:
    long cell_index(double v, double origin, double size) const {
        const double c = std::floor((v - origin) / size);
        return static_cast<long>(std::clamp(c, 0.0, static_cast<double>(g_ - 1)));
    }

    void rebuild() {
        double x1 = -std::numeric_limits<double>::infinity(), y1 = x1;
        x0_ = std::numeric_limits<double>::infinity(), y0_ = x0_;
        for (std::size_t id = 0; id < entries_.size(); ++id) {
            if (!alive_[id]) continue;
            const auto [x, y] = plane(entries_[id].point);
            x0_ = std::min(x0_, x), x1 = std::max(x1, x), y0_ = std::min(y0_, y),
            y1 = std::max(y1, y);
        }
        built_size_ = live_;
        g_ = std::clamp<std::size_t>(
            static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(live_) / 2.0))), 1,
            1024);
        w_ = std::max((x1 - x0_) / static_cast<double>(g_), 1e-9);
        h_ = std::max((y1 - y0_) / static_cast<double>(g_), 1e-9);
        if (!(w_ < std::numeric_limits<double>::infinity())) w_ = h_ = 1, x0_ = y0_ = 0;
        cells_.assign(g_ * g_, {});
        cell_of_entry_.assign(entries_.size(), 0);
        for (std::size_t id = 0; id < entries_.size(); ++id) {
            if (!alive_[id]) continue;
            const auto [x, y] = plane(entries_[id].point);
            const std::size_t c = static_cast<std::size_t>(cell_index(x, x0_, w_)) * g_ +
                                  static_cast<std::size_t>(cell_index(y, y0_, h_));
            cells_[c].push_back(id);
            cell_of_entry_[id] = c;
        }
    }

    std::vector<Entry> entries_;
    std::vector<bool> alive_;
    std::size_t live_ = 0, built_size_ = 0, g_ = 1;
    double x0_ = 0, y0_ = 0, w_ = 1, h_ = 1;
    std::vector<std::vector<std::size_t>> cells_;
    std::vector<std::size_t> cell_of_entry_;
};

/// Most starts of one loop the greedy search considers (evenly spread); refine_starts later
/// tries them all.
constexpr std::size_t kGreedyStartsPerLoop = 64;

/// Nearest neighbour from the start point over every item's allowed starts.
std::vector<Visit> greedy_order(const std::vector<Item>& items, const PathPoint& start) {
    std::vector<StartGrid::Entry> entries;
    std::vector<std::vector<std::size_t>> ids(items.size());
    for (std::size_t i = 0; i < items.size(); ++i) {
        const Item& it = items[i];
        if (it.cyclic) {
            const std::size_t count = it.starts.size();
            const std::size_t stride = (count + kGreedyStartsPerLoop - 1) / kGreedyStartsPerLoop;
            for (std::size_t c = 0; c < count; c += stride) {
                ids[i].push_back(entries.size());
                entries.push_back({it.starts[c], i, c});
            }
        } else if (!it.first.empty()) {
            ids[i].push_back(entries.size());
            entries.push_back({it.first, i, 0});
            ids[i].push_back(entries.size());
            entries.push_back({it.last, i, 1});
        }
    }
    std::vector<Visit> order;
    std::vector<bool> placed(items.size(), false);
    StartGrid grid(std::move(entries));
    PointRef here = start;
    for (;;) {
        const std::size_t id = grid.nearest(here);
        if (id == grid.size()) break;
        const StartGrid::Entry& e = grid.entry(id);
        const Item& it = items[e.item];
        order.push_back({e.item, e.choice});
        placed[e.item] = true;
        here = it.cyclic ? it.starts[e.choice] : PointRef(e.choice == 0 ? it.last : it.first);
        grid.remove_item(ids[e.item]);
    }
    // Items without a start (no points) keep their document place at the end.
    for (std::size_t i = 0; i < items.size(); ++i) {
        if (!placed[i]) order.push_back({i, 0});
    }
    return order;
}

/// 2-opt, Or-opt and start refinement until nothing improves or the work limit is spent.
void improve(Tour& tour) {
    const std::size_t n = tour.visits.size();
    // O(n^2) passes up to a few thousand items; beyond, a window keeps a pass near 4M moves.
    const std::size_t window = n <= 2000 ? n : std::max<std::size_t>(50, 4'000'000 / n);
    const std::size_t or_window = std::min<std::size_t>(window, 500);
    for (int round = 0; round < 50 && !tour.spent(); ++round) {
        bool changed = tour.refine_starts();
        changed = tour.two_opt(window) || changed;
        changed = tour.or_opt(or_window) || changed;
        changed = tour.refine_starts() || changed;
        if (!changed) break;
    }
}

/// The subpaths of `path` in the order of `visits`, reversed or rotated as chosen; those kept
/// as they are move out of a non-const `path` (each subpath is visited once).
template <class P>
Path build(P& path, const std::vector<Item>& items, const std::vector<Visit>& visits) {
    constexpr bool consume = !std::is_const_v<P>;
    Path out = without_subpaths(path);
    for (const Visit& v : visits) {
        const Item& it = items[v.item];
        auto& s = path.subpaths[it.subpath];
        if constexpr (consume) {  // moved, then reversed or rotated in place
            Subpath r = std::move(s);
            if (!it.cyclic) {
                if (v.choice != 0) reverse_points(r);
            } else if (r.closed) {
                rotate_points(r, it.shifts[v.choice]);
            } else {
                rotate_open_loop(r, it.shifts[v.choice]);
            }
            out.subpaths.push_back(std::move(r));
        } else if (!it.cyclic) {
            out.subpaths.push_back(v.choice == 0 ? s : reversed_subpath(s));
        } else if (s.closed) {
            out.subpaths.push_back(rotated_subpath(s, it.shifts[v.choice]));
        } else {
            out.subpaths.push_back(rotated_open_loop(s, it.shifts[v.choice]));
        }
    }
    return out;
}

/// Orders `path` (already joined) from `start`: greedy then improvement. A non-const `path`
/// is not needed afterwards: its subpaths may move into the result.
template <class P>
Path order_items(P& path, const PathPoint& start, const OrderOptions& o, bool greedy,
                 std::size_t& work) {
    const std::vector<Item> items = make_items(path, o.merge_tolerance);
    Tour tour(items, start, o.work_limit);
    if (greedy) {
        tour.visits = greedy_order(items, start);
    } else {
        for (std::size_t i = 0; i < items.size(); ++i) tour.visits.push_back({i, 0});
    }
    if (o.improve) improve(tour);
    work += tour.work();
    return build(path, items, tour.visits);
}

}  // namespace

PathPoint curve_start(const Subpath& s) {
    const std::size_t m = s.points.size();
    if (m == 0) return {};
    if (s.closed && s.basis == PathBasis::kBSpline && m >= 3) {
        PathPoint p(s.points.axes());
        for (std::size_t k = 0; k < p.size(); ++k) {
            p[k] = (s.points[m - 1][k] + 4 * s.points[0][k] + s.points[1][k]) / 6;
        }
        return p;
    }
    return s.points.front();
}

PathPoint curve_end(const Subpath& s) {
    return s.closed ? curve_start(s) : (s.points.empty() ? PathPoint{} : s.points.back().vector());
}

double pen_up_travel(const Path& path, const PathPoint& start) {
    PathPoint here = start.empty() ? PathPoint(path.axes, 0.0) : start;
    double total = 0;
    for (const Subpath& s : path.subpaths) {
        if (s.points.empty()) continue;
        total += distance(here, curve_start(s));
        here = curve_end(s);
    }
    return total;
}

Subpath reversed_subpath(const Subpath& s) {
    Subpath r = s;
    reverse_points(r);
    return r;
}

Subpath rotated_subpath(const Subpath& s, std::size_t shift) {
    if (!s.closed) throw std::invalid_argument("rotated_subpath: the subpath is open");
    Subpath r = s;
    rotate_points(r, shift);
    return r;
}

namespace {
/// A subpath merge_touching may join at its ends: open, of a joinable basis, points valid, not
/// resting at its joints (the join would lose the rest at its own ends).
bool joinable(const Subpath& s) {
    return !s.closed && joinable_basis(s.basis) && s.points.size() >= 2 &&
           point_count_problem(s).empty() && s.corner_mode != CornerMode::kExactStop;
}

/// Whether two subpaths may become one: the same feed and the same corner rule.
bool same_motion(const Subpath& a, const Subpath& b) {
    return a.feed == b.feed && a.corner_mode == b.corner_mode &&
           a.blend_tolerance == b.blend_tolerance;
}

/// The grid cell (side `cell`, mm) of an end point in the plane: ends within `cell` of each
/// other lie in the same or neighbouring cells.
using EndCell = std::pair<long long, long long>;
EndCell end_cell(PointRef p, double cell) {
    const auto [x, y] = plane(p);
    return EndCell{static_cast<long long>(std::floor(x / cell)),
                   static_cast<long long>(std::floor(y / cell))};
}

/// A polyline as the Bezier chain the planner draws of it: control points at the thirds, as
/// geometry.cpp's straight segments.
void to_bezier_chain(Subpath& s) {
    PointList chain;
    chain.reserve(3 * s.points.size(), s.points.axes());
    chain.push_back(s.points.front());
    PathPoint c(s.points.axes());
    for (std::size_t i = 1; i < s.points.size(); ++i) {
        const PointRef a = s.points[i - 1], b = s.points[i];
        for (const auto& [wa, wb] : {std::pair{2.0 / 3, 1.0 / 3}, std::pair{1.0 / 3, 2.0 / 3}}) {
            for (std::size_t k = 0; k < c.size(); ++k) c[k] = wa * a[k] + wb * b[k];
            chain.push_back(c);
        }
        chain.push_back(b);
    }
    s.points = std::move(chain);
    s.basis = PathBasis::kBezier;
}

/// Two joinable subpaths made one basis for joining: a polyline meeting a Bezier chain (an SVG
/// path of lines only and one with curves) becomes a Bezier chain too.
void same_basis(Subpath& a, Subpath& b) {
    if (a.basis == b.basis) return;
    to_bezier_chain(a.basis == PathBasis::kPolyline ? a : b);
}

/// Whether merge_touching would join anything: two joinable subpaths of one feed
/// with ends within `tolerance` (a superset of its joins: false means it joins none).
bool any_touching(const Path& path, double tolerance) {
    if (tolerance < 0) return false;
    const auto& in = path.subpaths;
    const double cell = std::max(tolerance, 1e-9);
    using Key = EndCell;
    const auto key = [&](PointRef p) { return end_cell(p, cell); };
    std::map<Key, std::vector<std::pair<std::size_t, PointRef>>> ends;
    for (std::size_t i = 0; i < in.size(); ++i) {
        if (!joinable(in[i])) continue;
        for (const PointRef p : {in[i].points.front(), in[i].points.back()})
            ends[key(p)].push_back({i, p});
    }
    for (const auto& [k, list] : ends) {
        for (const auto& [i, p] : list) {
            for (long long dx = -1; dx <= 1; ++dx) {
                for (long long dy = -1; dy <= 1; ++dy) {
                    const auto found = ends.find({k.first + dx, k.second + dy});
                    if (found == ends.end()) continue;
                    for (const auto& [j, q] : found->second) {
                        const Subpath &a = in[i], &b = in[j];
                        if (j == i || !same_motion(a, b) || p.size() != q.size()) continue;
                        if (distance(p, q) <= tolerance) return true;
                    }
                }
            }
        }
    }
    return false;
}
}  // namespace

Path merge_touching(const Path& path, double tolerance, std::size_t* merged) {
    std::size_t joins = 0;
    if (tolerance < 0) {
        if (merged != nullptr) *merged = 0;
        return path;
    }
    Path out = without_subpaths(path);
    const auto& in = path.subpaths;
    // End points of joinable subpaths by grid cell (cell size: the tolerance).
    const double cell = std::max(tolerance, 1e-9);
    using Key = EndCell;
    const auto key = [&](PointRef p) { return end_cell(p, cell); };
    std::map<Key, std::vector<std::pair<std::size_t, int>>> ends;  // subpath, 0 first / 1 last
    for (std::size_t i = 0; i < in.size(); ++i) {
        if (!joinable(in[i])) continue;
        ends[key(in[i].points.front())].push_back({i, 0});
        ends[key(in[i].points.back())].push_back({i, 1});
    }
    std::vector<bool> used(in.size(), false);
    // The lowest-index unused compatible subpath with an end within the tolerance of p.
    const auto find = [&](const Subpath& with, PointRef p) {
        std::pair<std::size_t, int> best{in.size(), 0};
        const Key k = key(p);
        for (long long dx = -1; dx <= 1; ++dx) {
            for (long long dy = -1; dy <= 1; ++dy) {
                const auto found = ends.find({k.first + dx, k.second + dy});
                if (found == ends.end()) continue;
                auto& list = found->second;
                list.erase(std::remove_if(list.begin(), list.end(),
                                          [&](const auto& e) { return used[e.first]; }),
                           list.end());
                for (const auto& [i, side] : list) {
                    const Subpath& s = in[i];
                    if (!same_motion(s, with) || s.points[0].size() != p.size()) continue;
                    const PointRef q = side == 0 ? s.points.front() : s.points.back();
                    if (distance(p, q) > tolerance) continue;
                    if (i < best.first || (i == best.first && side < best.second)) best = {i, side};
                }
            }
        }
        return best;
    };
    for (std::size_t a = 0; a < in.size(); ++a) {
        if (used[a]) continue;
        used[a] = true;
        out.subpaths.push_back(in[a]);
        if (!joinable(in[a])) continue;
        Subpath& chain = out.subpaths.back();
        const std::size_t joins_before = joins;
        for (;;) {  // forward from the chain's last point
            const auto [b, side] = find(chain, chain.points.back());
            if (b == in.size()) break;
            used[b] = true;
            ++joins;
            Subpath next = side == 0 ? in[b] : reversed_subpath(in[b]);
            same_basis(chain, next);
            chain.points.append(next.points, 1, next.points.size());
        }
        for (;;) {  // backward from the chain's first point
            const auto [b, side] = find(chain, chain.points.front());
            if (b == in.size()) break;
            used[b] = true;
            ++joins;
            Subpath prev = side == 1 ? in[b] : reversed_subpath(in[b]);
            same_basis(chain, prev);
            chain.points.prepend(prev.points, 0, prev.points.size() - 1);
        }
        if (joins != joins_before)
            chain.segment_lines.clear();  // joined: the lines no longer match
    }
    if (merged != nullptr) *merged = joins;
    return out;
}

Path order_path(const Path& path, const OrderOptions& o, OrderReport* report) {
    const PathPoint start = o.start.empty() ? PathPoint(path.axes, 0.0) : o.start;
    if (start.size() != path.axes) {
        throw std::invalid_argument("order: the start point has " + std::to_string(start.size()) +
                                    " coordinates, the path " + std::to_string(path.axes) +
                                    " axes");
    }
    OrderReport r;
    r.subpaths_before = path.subpaths.size();
    r.travel_before = pen_up_travel(path, start);
    // Joined into a copy only when some ends touch: a 10^6-point path is ~60 MB a copy.
    Path best;
    if (any_touching(path, o.merge_tolerance)) {
        Path joined = merge_touching(path, o.merge_tolerance, &r.merged);
        best = order_items(joined, start, o, true, r.work);
    } else {
        best = order_items(path, start, o, true, r.work);
    }
    double best_travel = pen_up_travel(best, start);
    // Greedy may lose to a good document order: improve that instead (never worse than it).
    if (best_travel > r.travel_before) {
        OrderOptions plain = o;
        plain.merge_tolerance = -1;
        best = Path{};  // not held while the next is built
        best = order_items(path, start, plain, false, r.work);
        best_travel = pen_up_travel(best, start);
        r.merged = 0;
        if (best_travel > r.travel_before) best = path, best_travel = r.travel_before;
    }
    r.travel_after = best_travel;
    r.subpaths_after = best.subpaths.size();
    if (report != nullptr) *report = r;
    return best;
}

}  // namespace pathstream::host
