#include "pathstream/sim/contour_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace pathstream::sim {
namespace {

constexpr std::uint64_t kBlock = 16;  // vertices per bounding box

}  // namespace

std::uint64_t contour_back_ticks(double tick_hz, double lag_seconds) {
    const double lag_ticks = std::ceil(4 * std::max(0.0, lag_seconds) * tick_hz);
    return static_cast<std::uint64_t>(std::min(4096.0, 64 + lag_ticks));
}

ContourErrorMeter::ContourErrorMeter(std::size_t axes, std::uint64_t back_ticks,
                                     std::uint64_t ahead_ticks)
    : axes_(axes), back_(back_ticks), ahead_(ahead_ticks) {
    if (axes == 0 || axes > 8 || back_ticks == 0)
        throw std::invalid_argument("contour error needs 1 to 8 axes and a window of a tick");
    // Kept: the vertices from the one in effect 2 back ticks before the tool tick evaluated
    // last (the snapshot's start) to the newest, and the tool points of those ticks.
    vertex_capacity_ = 2 * back_ + ahead_ + 2;
    tool_capacity_ = 2 * back_ + ahead_ + 1;
    vertex_mm_.assign(vertex_capacity_ * axes, 0.0);
    vertex_ticks_.assign(vertex_capacity_, 0);
    tool_mm_.assign(tool_capacity_ * axes, 0.0);
    block_capacity_ = vertex_capacity_ / kBlock + 3;
    block_lo_.assign(block_capacity_ * axes, 0.0);
    block_hi_.assign(block_capacity_ * axes, 0.0);
    r_.back_ticks = back_;
    r_.ahead_ticks = ahead_;
    r_.window.axes = axes;
}

const double* ContourErrorMeter::vertex(std::uint64_t index) const {
    return &vertex_mm_[(index % vertex_capacity_) * axes_];
}

std::uint64_t ContourErrorMeter::vertex_tick(std::uint64_t index) const {
    return vertex_ticks_[index % vertex_capacity_];
}

const double* ContourErrorMeter::tool(std::uint64_t tick) const {
    return &tool_mm_[(tick % tool_capacity_) * axes_];
}

void ContourErrorMeter::add(const double* reference_mm, const double* tool_mm) {
    const std::uint64_t k = ticks_++;
    bool repeated = vertices_ > 0;
    if (repeated) {
        const double* last = vertex(vertices_ - 1);
        for (std::size_t a = 0; a < axes_; ++a) repeated = repeated && reference_mm[a] == last[a];
    }
    if (!repeated) {
        std::copy(reference_mm, reference_mm + axes_,
                  vertex_mm_.begin() +
                      static_cast<std::ptrdiff_t>((vertices_ % vertex_capacity_) * axes_));
        vertex_ticks_[vertices_ % vertex_capacity_] = k;
        // The vertex's block, and the block before when it is that one's closing vertex.
        const std::uint64_t b = vertices_ / kBlock;
        for (std::uint64_t block = b > 0 && vertices_ % kBlock == 0 ? b - 1 : b; block <= b;
             ++block) {
            double* lo = &block_lo_[(block % block_capacity_) * axes_];
            double* hi = &block_hi_[(block % block_capacity_) * axes_];
            const bool first = block == b && vertices_ % kBlock == 0;
            for (std::size_t a = 0; a < axes_; ++a) {
                lo[a] = first ? reference_mm[a] : std::min(lo[a], reference_mm[a]);
                hi[a] = first ? reference_mm[a] : std::max(hi[a], reference_mm[a]);
            }
        }
        ++vertices_;
    }
    std::copy(tool_mm, tool_mm + axes_,
              tool_mm_.begin() + static_cast<std::ptrdiff_t>((k % tool_capacity_) * axes_));
    if (k >= ahead_) evaluate(k - ahead_);
}

void ContourErrorMeter::scan(std::uint64_t first, std::uint64_t last) {
    const double* p = point_;
    for (std::uint64_t i = first; i <= last; ++i) {
        const double* a = vertex(i);
        double squares = 0;
        for (std::size_t x = 0; x < axes_; ++x) squares += (p[x] - a[x]) * (p[x] - a[x]);
        if (squares < best_) best_ = squares, best_vertex_ = i, best_t_ = 0;
        if (i + 1 >= vertices_) continue;
        const double* b = vertex(i + 1);
        double ab_ab = 0, ap_ab = 0;
        for (std::size_t x = 0; x < axes_; ++x) {
            const double ab = b[x] - a[x];
            ab_ab += ab * ab;
            ap_ab += (p[x] - a[x]) * ab;
        }
        if (!(ap_ab > 0) || !(ab_ab > 0)) continue;  // the vertex is nearest: done above
        const double t = std::min(1.0, ap_ab / ab_ab);
        squares = 0;
        for (std::size_t x = 0; x < axes_; ++x) {
            const double d = p[x] - (a[x] + t * (b[x] - a[x]));
            squares += d * d;
        }
        if (squares < best_) best_ = squares, best_vertex_ = i, best_t_ = t;
    }
}

void ContourErrorMeter::evaluate(std::uint64_t j) {
    point_ = tool(j);
    const std::uint64_t from = j > back_ ? j - back_ : 0;
    const std::uint64_t newest = vertices_ - 1;
    while (start_ < newest && vertex_tick(start_ + 1) <= from) ++start_;
    while (own_ < newest && vertex_tick(own_ + 1) <= j) ++own_;
    // The vertices from the one in effect at tick `from` to the newest: the block of the
    // tool's own tick first (the nearest point is about there), then every block whose box is
    // nearer than the best point yet.
    best_ = std::numeric_limits<double>::infinity();
    const auto scan_block = [&](std::uint64_t block) {
        scan(std::max(start_, block * kBlock), std::min(newest, block * kBlock + kBlock - 1));
    };
    const std::uint64_t own_block = own_ / kBlock;
    scan_block(own_block);
    for (std::uint64_t block = start_ / kBlock; block <= newest / kBlock; ++block) {
        if (block == own_block) continue;
        const double* lo = &block_lo_[(block % block_capacity_) * axes_];
        const double* hi = &block_hi_[(block % block_capacity_) * axes_];
        double squares = 0;
        for (std::size_t x = 0; x < axes_; ++x) {
            const double d = std::max({lo[x] - point_[x], 0.0, point_[x] - hi[x]});
            squares += d * d;
        }
        if (squares < best_) scan_block(block);
    }
    const double distance = std::sqrt(best_);
    sum_squares_ += best_;
    if (r_.max_tool_mm.empty() || distance > r_.max_mm) {
        r_.max_mm = distance;
        r_.max_tick = j;
        r_.max_tool_mm.assign(point_, point_ + axes_);
        const double* a = vertex(best_vertex_);
        r_.max_path_mm.assign(a, a + axes_);
        if (best_t_ > 0) {
            const double* b = vertex(best_vertex_ + 1);
            for (std::size_t x = 0; x < axes_; ++x) r_.max_path_mm[x] += best_t_ * (b[x] - a[x]);
        }
        pending_ = true;
    }
    if (pending_ && j == r_.max_tick + back_) snapshot(j);
}

void ContourErrorMeter::snapshot(std::uint64_t last_tool_tick) {
    pending_ = false;
    const std::uint64_t centre = r_.max_tick;
    const std::uint64_t first = centre > back_ ? centre - back_ : 0;
    const std::uint64_t last = std::min(last_tool_tick, ticks_ - 1);
    ContourWindow& w = r_.window;
    w.first_tool_tick = first;
    w.tool_mm.clear();
    for (std::uint64_t k = first; k <= last; ++k)
        w.tool_mm.insert(w.tool_mm.end(), tool(k), tool(k) + axes_);
    // The vertices in effect from tick `first` to tick `last`.
    std::uint64_t i = vertices_;
    while (i > 0 && vertex_tick(i - 1) > last) --i;
    std::uint64_t start = i;
    while (start > 0 && vertex_tick(start - 1) > first) --start;
    if (start > 0) --start;  // the one in effect at `first`
    w.path_mm.clear();
    for (std::uint64_t v = start; v < i; ++v)
        w.path_mm.insert(w.path_mm.end(), vertex(v), vertex(v) + axes_);
}

ContourError ContourErrorMeter::finish() {
    const std::uint64_t first = ticks_ > ahead_ ? ticks_ - ahead_ : 0;
    for (std::uint64_t j = first; j < ticks_; ++j) evaluate(j);
    if (pending_ && ticks_ > 0) snapshot(ticks_ - 1);
    if (ticks_ > 0) r_.rms_mm = std::sqrt(sum_squares_ / static_cast<double>(ticks_));
    return std::move(r_);
}

}  // namespace pathstream::sim
