// Distance from a point to the geometric path (nearest point on the Bezier segments).
#include "projection.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

#include "cubic.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

PathProjector::PathProjector(std::vector<Cubic> segments, std::vector<std::size_t> index,
                             double global_below)
    : segs_(std::move(segments)), index_(std::move(index)), global_below_(global_below) {
    for (const Cubic& c : segs_) {
        length_.push_back(arc_length(c, 0, 0.5) + arc_length(c, 0.5, 1));
        Vec lo = c.p[0], hi = c.p[0];
        for (const Vec& p : c.p) {
            for (std::size_t i = 0; i < kAxesMax; ++i) {
                lo[i] = std::min(lo[i], p[i]);
                hi[i] = std::max(hi[i], p[i]);
            }
        }
        lo_.push_back(lo);
        hi_.push_back(hi);
    }
    order_.resize(segs_.size());
    for (std::size_t i = 0; i < order_.size(); ++i) order_[i] = i;
    if (!segs_.empty()) {
        tree_.reserve(2 * segs_.size() / 4 + 2);
        build_tree(0, segs_.size());
    }
    // Runs of segments that join end to start; a closed run (ending where it starts) wraps
    // around in the search window.
    run_first_.resize(segs_.size());
    run_last_.resize(segs_.size());
    for (std::size_t i = 0; i < segs_.size();) {
        std::size_t e = i;
        while (e + 1 < segs_.size() && segs_[e + 1].p[0] == segs_[e].p[3]) ++e;
        for (std::size_t k = i; k <= e; ++k) {
            run_first_[k] = i;
            run_last_[k] = e;
        }
        i = e + 1;
    }
}

std::size_t PathProjector::build_tree(std::size_t first, std::size_t last) {
    const std::size_t id = tree_.size();
    tree_.push_back({});
    Vec lo = lo_[order_[first]], hi = hi_[order_[first]];
    for (std::size_t k = first; k < last; ++k) {
        for (std::size_t a = 0; a < kAxesMax; ++a) {
            lo[a] = std::min(lo[a], lo_[order_[k]][a]);
            hi[a] = std::max(hi[a], hi_[order_[k]][a]);
        }
    }
    tree_[id].lo = lo;
    tree_[id].hi = hi;
    tree_[id].first = first;
    tree_[id].last = last;
    if (last - first <= 4) return id;
    // Median split along the widest axis of the box centres.
    std::size_t axis = 0;
    for (std::size_t a = 1; a < kAxesMax; ++a) {
        if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
    }
    const std::size_t mid = first + (last - first) / 2;
    const auto centre = [&](std::size_t i) { return lo_[i][axis] + hi_[i][axis]; };
    std::nth_element(order_.begin() + static_cast<std::ptrdiff_t>(first),
                     order_.begin() + static_cast<std::ptrdiff_t>(mid),
                     order_.begin() + static_cast<std::ptrdiff_t>(last),
                     [&](std::size_t a, std::size_t b) { return centre(a) < centre(b); });
    const std::size_t left = build_tree(first, mid);
    const std::size_t right = build_tree(mid, last);
    tree_[id].left = left;
    tree_[id].right = right;
    return id;
}

namespace {

/// Distance from p to an axis-aligned box.
double distance_to_box(const Vec& lo, const Vec& hi, const Vec& p) {
    double s = 0;
    for (std::size_t a = 0; a < kAxesMax; ++a) {
        const double d = p[a] < lo[a] ? lo[a] - p[a] : (p[a] > hi[a] ? p[a] - hi[a] : 0.0);
        s += d * d;
    }
    return std::sqrt(s);
}

}  // namespace

template <typename Consider>
void PathProjector::search_tree(const Vec& p, double& best, Consider&& consider) const {
    if (tree_.empty()) return;
    std::vector<std::size_t> stack{0};
    while (!stack.empty()) {
        const TreeNode& node = tree_[stack.back()];
        stack.pop_back();
        if (distance_to_box(node.lo, node.hi, p) >= best) continue;
        if (node.left == 0 && node.right == 0) {
            for (std::size_t k = node.first; k < node.last; ++k) consider(order_[k]);
            continue;
        }
        // The nearer child is examined first (pushed last): it lowers `best` sooner.
        const double dl = distance_to_box(tree_[node.left].lo, tree_[node.left].hi, p);
        const double dr = distance_to_box(tree_[node.right].lo, tree_[node.right].hi, p);
        stack.push_back(dl <= dr ? node.right : node.left);
        stack.push_back(dl <= dr ? node.left : node.right);
    }
}

double PathProjector::box_distance(std::size_t i, const Vec& p) const {
    double s = 0;
    for (std::size_t a = 0; a < kAxesMax; ++a) {
        const double d =
            p[a] < lo_[i][a] ? lo_[i][a] - p[a] : (p[a] > hi_[i][a] ? p[a] - hi_[i][a] : 0.0);
        s += d * d;
    }
    return std::sqrt(s);
}

namespace {

/// Squared distance from p to the box of the control points (a lower bound for the curve).
double box_distance2(const Cubic& c, const Vec& p) {
    double s = 0;
    for (std::size_t a = 0; a < kAxesMax; ++a) {
        const double lo = std::min(std::min(c.p[0][a], c.p[1][a]), std::min(c.p[2][a], c.p[3][a]));
        const double hi = std::max(std::max(c.p[0][a], c.p[1][a]), std::max(c.p[2][a], c.p[3][a]));
        const double d = p[a] < lo ? lo - p[a] : (p[a] > hi ? p[a] - hi : 0.0);
        s += d * d;
    }
    return s;
}

/// de Casteljau split at the middle.
void split(const Cubic& c, Cubic& left, Cubic& right) {
    for (std::size_t a = 0; a < kAxesMax; ++a) {
        const double p01 = 0.5 * (c.p[0][a] + c.p[1][a]), p12 = 0.5 * (c.p[1][a] + c.p[2][a]),
                     p23 = 0.5 * (c.p[2][a] + c.p[3][a]);
        const double p012 = 0.5 * (p01 + p12), p123 = 0.5 * (p12 + p23), mid = 0.5 * (p012 + p123);
        left.p[0][a] = c.p[0][a];
        left.p[1][a] = p01;
        left.p[2][a] = p012;
        left.p[3][a] = mid;
        right.p[0][a] = mid;
        right.p[1][a] = p123;
        right.p[2][a] = p23;
        right.p[3][a] = c.p[3][a];
    }
}

/// Largest distance of the inner control points from the chord: how far from straight. A
/// piece whose control polygon turns back along the chord (a cusp) is not straight at all.
double flatness(const Cubic& c) {
    const Vec chord = sub(c.p[3], c.p[0]);
    const double len2 = dot(chord, chord);
    double worst = 0;
    for (int k = 1; k <= 2; ++k) {
        const Vec off = sub(c.p[k], c.p[0]);
        const double w = len2 > 0 ? dot(off, chord) / len2 : 0;
        worst = std::max(worst, norm(sub(off, scaled(chord, w))));
    }
    for (int k = 0; k < 3; ++k) {
        if (dot(sub(c.p[k + 1], c.p[k]), chord) < 0) return std::numeric_limits<double>::infinity();
    }
    return worst;
}

}  // namespace

double PathProjector::segment_distance(std::size_t i, const Vec& p, double bound,
                                       double* at) const {
    // Branch and bound: a piece of the curve lies in the box of its control points, so a piece
    // whose box is farther than the best distance so far is dropped; nearly straight pieces
    // are projected on their chord and the parameter refined by Newton on the whole segment.
    const Cubic& whole = segs_[i];
    struct Item {
        Cubic c;
        double u0, u1;
        int depth;
    };
    Item stack[64];
    std::size_t n = 0;
    stack[n++] = {whole, 0.0, 1.0, 0};
    double best = bound * bound;  // only a nearer point matters: prunes against the best so far
    while (n > 0) {
        const Item it = stack[--n];
        if (box_distance2(it.c, p) >= best) continue;
        if (it.depth >= 30 || flatness(it.c) <= 1e-3 || n + 2 > 64) {
            // On a nearly straight piece the nearest point is where the curve passes p's
            // projection on the chord: (q(u) - p) . chord = 0, found by Illinois regula falsi
            // (robust where q' vanishes, e.g. handles on the end points).
            const Vec chord = sub(it.c.p[3], it.c.p[0]);
            const auto g = [&](double v) { return dot(sub(whole.point(v), p), chord); };
            double lo = it.u0, hi = it.u1, glo = g(lo), ghi = g(hi);
            double u = glo >= 0 ? lo : (ghi <= 0 ? hi : 0.5 * (lo + hi));
            int side = 0;
            for (int k = 0; k < 200 && glo < 0 && ghi > 0 && hi - lo > 1e-15; ++k) {
                u = lo - glo * (hi - lo) / (ghi - glo);
                if (!(u > lo && u < hi)) u = 0.5 * (lo + hi);
                const double gu = g(u);
                if (gu == 0) break;
                if (gu < 0) {
                    lo = u;
                    glo = gu;
                    if (side == -1) ghi *= 0.5;
                    side = -1;
                } else {
                    hi = u;
                    ghi = gu;
                    if (side == +1) glo *= 0.5;
                    side = +1;
                }
            }
            for (const double v : {u, it.u0, it.u1}) {
                const Vec d = sub(whole.point(v), p);
                if (dot(d, d) < best) {
                    best = dot(d, d);
                    if (at != nullptr) *at = v;
                }
            }
            continue;
        }
        Item left{{}, it.u0, 0.5 * (it.u0 + it.u1), it.depth + 1},
            right{{}, left.u1, it.u1, it.depth + 1};
        split(it.c, left.c, right.c);
        // The nearer half is examined first (pushed last): it tightens the bound sooner.
        if (box_distance2(left.c, p) <= box_distance2(right.c, p)) {
            stack[n++] = right;
            stack[n++] = left;
        } else {
            stack[n++] = left;
            stack[n++] = right;
        }
    }
    return std::sqrt(best);
}

PathProjector::Cursor PathProjector::cursor() const {
    Cursor c;
    c.segment = started_ && cursor_ < index_.size() ? index_[cursor_] : 0;
    c.u = last_u_;
    c.p = last_p_;
    c.d = last_d_;
    c.started = started_ && cursor_ < index_.size();
    return c;
}

void PathProjector::resume(const Cursor& c) {
    const auto it = std::lower_bound(index_.begin(), index_.end(), c.segment);
    if (!c.started || it == index_.end() || *it != c.segment) return;
    cursor_ = static_cast<std::size_t>(it - index_.begin());
    last_u_ = c.u;
    last_p_ = c.p;
    last_d_ = c.d;
    started_ = true;
}

double PathProjector::follow(const Vec& p) {
    if (!started_ || cursor_ >= segs_.size()) return std::numeric_limits<double>::infinity();
    double u = last_u_;
    for (int hop = 0; hop < 4; ++hop) {
        const Cubic& c = segs_[cursor_];
        for (int it = 0; it < 4; ++it) {
            // Newton on (q(u) - p) . q'(u) = 0 over the used axes only (this runs every tick).
            const double v = 1 - u;
            double f = 0, df = 0;
            for (std::size_t i = 0; i < c.axes; ++i) {
                const double p0 = c.p[0][i], p1 = c.p[1][i], p2 = c.p[2][i], p3 = c.p[3][i];
                const double a = v * p0 + u * p1, b = v * p1 + u * p2, e = v * p2 + u * p3;
                const double d = v * (v * a + u * b) + u * (v * b + u * e) - p[i];
                const double d1 =
                    3 * (v * v * (p1 - p0) + 2 * u * v * (p2 - p1) + u * u * (p3 - p2));
                const double d2 = 6 * (v * (p2 - 2 * p1 + p0) + u * (p3 - 2 * p2 + p1));
                f += d * d1;
                df += d1 * d1 + d * d2;
            }
            if (!(df > 0)) break;
            const double next = std::clamp(u - f / df, 0.0, 1.0);
            const bool settled = std::fabs(next - u) < 1e-10;  // any further step moves < 1 nm
            u = next;
            if (settled) break;
        }
        if (u >= 1 && cursor_ + 1 < segs_.size() && segs_[cursor_ + 1].p[0] == c.p[3]) {
            ++cursor_;
            u = 0;
        } else if (u <= 0 && cursor_ > 0 && segs_[cursor_ - 1].p[3] == c.p[0]) {
            --cursor_;
            u = 1;
        } else {
            break;
        }
    }
    last_u_ = u;
    last_d_ = norm(sub(segs_[cursor_].point(u), p));
    last_p_ = p;
    return last_d_;
}

double PathProjector::distance(const Vec& p, std::size_t& segment) {
    const std::size_t n = segs_.size();
    const double step = started_ ? norm(sub(p, last_p_)) : 0;
    const double reach = 2 * (step + last_d_) + 0.01;  // mm of path to search ahead
    double best = std::numeric_limits<double>::infinity();
    std::size_t best_i = cursor_;
    // Around the cursor, both ways, until `reach` mm of path (at least two segments each way).
    std::size_t from = cursor_;
    for (double behind = 0; from > 0 && (from + 2 > cursor_ || behind <= reach);)
        behind += length_[--from];
    double best_u = 0;
    const auto consider = [&](std::size_t i) {
        if (box_distance(i, p) >= best) return;
        double u = 0;
        const double d = segment_distance(i, p, best, &u);
        if (d < best) {
            best = d;
            best_i = i;
            best_u = u;
        }
    };
    if (started_ && cursor_ < n) {
        // Any point of the path bounds the distance from above: the cursor segment's point
        // nearest p by Newton from the last answer's parameter, so that the searches below
        // prune nearly every box at once.
        const Cubic& c = segs_[cursor_];
        double u = last_u_;
        for (int it = 0; it < 3; ++it) {
            const Vec d = sub(c.point(u), p), d1 = c.d1(u), d2 = c.d2(u);
            const double f = dot(d, d1), df = dot(d1, d1) + dot(d, d2);
            if (!(df > 0)) break;
            u = std::clamp(u - f / df, 0.0, 1.0);
        }
        best = norm(sub(c.point(u), p)) * (1 + 1e-12) + 1e-15;
        best_u = u;
    }
    if (n > 0) consider(std::min(cursor_, n - 1));  // the cursor's own segment wins ties
    double ahead = 0;
    for (std::size_t i = from; i < n && i < from + 10000; ++i) {
        if (i > cursor_ + 2 && ahead > reach) break;
        if (i > cursor_) ahead += length_[i - 1];
        consider(i);
    }
    if (n > 0 &&
        segs_[run_last_[cursor_]].p[3] == segs_[run_first_[cursor_]].p[0]) {  // closed: wrap
        for (const std::size_t i : {run_first_[cursor_], run_first_[cursor_] + 1,
                                    run_last_[cursor_], run_last_[cursor_] - 1}) {
            if (i >= run_first_[cursor_] && i <= run_last_[cursor_]) consider(i);
        }
    }
    if (!(best <= global_below_) || !started_) {  // not close around the cursor: every segment
        search_tree(p, best, consider);
    }
    cursor_ = best_i;
    last_u_ = best_u;
    last_p_ = p;
    last_d_ = best;
    started_ = true;
    segment = n > 0 ? index_[best_i] : 0;
    return best;
}

}  // namespace pathstream::host::planner_detail
