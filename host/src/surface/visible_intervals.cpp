// A curve's visible parts: samples close enough on the drawing to see any hidden stretch of
// about their spacing, and each change between seen and hidden bisected to the tolerance.
#include <algorithm>
#include <array>
#include <cmath>

#include "pathstream/host/hidden_lines.hpp"

namespace pathstream::host {
namespace {

// Homogeneous de Casteljau: the curve's point at t, and (with `left`/`right`) its halves.
using H = std::array<double, 4>;

std::vector<H> homogeneous(const std::vector<Point3>& q, const std::vector<double>& w) {
    std::vector<H> h;
    for (std::size_t i = 0; i < q.size(); ++i) {
        const double wi = w.empty() ? 1.0 : w[i];
        h.push_back({wi * q[i][0], wi * q[i][1], wi * q[i][2], wi});
    }
    return h;
}

void split(const std::vector<H>& h, double t, std::vector<H>* left, std::vector<H>* right) {
    std::vector<H> work = h;
    const std::size_t n = h.size();
    if (left) left->assign(1, work[0]);
    if (right) right->assign(1, work[n - 1]);
    for (std::size_t r = n - 1; r > 0; --r) {
        for (std::size_t i = 0; i < r; ++i) {
            for (int k = 0; k < 4; ++k) work[i][k] = (1 - t) * work[i][k] + t * work[i + 1][k];
        }
        if (left) left->push_back(work[0]);
        if (right) right->push_back(work[r - 1]);
    }
    if (right) std::reverse(right->begin(), right->end());
}

Point3 point_at(const std::vector<H>& h, double t) {
    std::vector<H> left;
    split(h, t, &left, nullptr);
    const H& e = left.back();
    return {e[0] / e[3], e[1] / e[3], e[2] / e[3]};
}

double apart(const ViewFrame& f, const Point3& a, const Point3& b) {
    const auto pa = project_point(f, a), pb = project_point(f, b);
    return std::hypot(pa[0] - pb[0], pa[1] - pb[1]);
}

}  // namespace

std::vector<Point3> bezier_piece(const std::vector<Point3>& q, std::vector<double>& weights,
                                 double t0, double t1) {
    const bool rational = !weights.empty();
    std::vector<H> left, piece;
    split(homogeneous(q, weights), t1, &left, nullptr);
    split(left, t1 > 0 ? t0 / t1 : 0, nullptr, &piece);
    std::vector<Point3> out;
    weights.clear();
    for (const H& e : piece) {
        out.push_back({e[0] / e[3], e[1] / e[3], e[2] / e[3]});
        if (rational) weights.push_back(e[3]);
    }
    return out;
}

std::vector<std::array<double, 2>> visible_intervals(const std::vector<Point3>& q,
                                                     const std::vector<double>& weights,
                                                     const ViewFrame& frame,
                                                     const Occluder& occluder, double tolerance_mm,
                                                     double sample_mm) {
    const std::vector<H> h = homogeneous(q, weights);
    double polygon = 0;
    for (std::size_t i = 1; i < q.size(); ++i) polygon += apart(frame, q[i - 1], q[i]);
    // The control polygon is at least as long as the curve (rational ones: near enough).
    const double wanted = std::ceil(polygon / std::max(sample_mm, 1e-9));
    const std::size_t n = static_cast<std::size_t>(std::clamp(wanted, 8.0, 4096.0));
    std::vector<std::array<double, 2>> out;
    auto seen = [&](double t) { return !occluder.hidden(point_at(h, t)); };
    // Narrows [lo, hi] (seen at `lo_seen`, the other at hi) to the tolerance on the drawing;
    // returns the seen end.
    auto locate = [&](double lo, double hi, bool lo_seen) {
        while (apart(frame, point_at(h, lo), point_at(h, hi)) > tolerance_mm && hi - lo > 1e-12) {
            const double mid = (lo + hi) / 2;
            if (seen(mid) == lo_seen) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        return lo_seen ? lo : hi;
    };
    bool prev = seen(0);
    double start = 0;
    for (std::size_t k = 1; k <= n; ++k) {
        const double t = static_cast<double>(k) / static_cast<double>(n);
        const double t_prev = static_cast<double>(k - 1) / static_cast<double>(n);
        const bool now = seen(t);
        if (now != prev) {
            if (prev) {
                out.push_back({start, locate(t_prev, t, true)});
            } else {
                // Bisect from the seen side: locate keeps `lo` seen, so swap the roles.
                double lo = t_prev, hi = t;
                while (apart(frame, point_at(h, lo), point_at(h, hi)) > tolerance_mm &&
                       hi - lo > 1e-12) {
                    const double mid = (lo + hi) / 2;
                    if (seen(mid)) {
                        hi = mid;
                    } else {
                        lo = mid;
                    }
                }
                start = hi;
            }
            prev = now;
        }
    }
    if (prev) out.push_back({start, 1.0});
    // Stretches shorter than the tolerance on the drawing are not worth a pen-down.
    std::erase_if(out, [&](const std::array<double, 2>& iv) {
        return apart(frame, point_at(h, iv[0]), point_at(h, iv[1])) < tolerance_mm &&
               apart(frame, point_at(h, iv[0]), point_at(h, (iv[0] + iv[1]) / 2)) < tolerance_mm;
    });
    return out;
}

}  // namespace pathstream::host
