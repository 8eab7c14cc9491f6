#include "pathstream/sim/contour_error.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace pathstream::sim {

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
    nearest_.assign(axes, 0.0);
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
        ++vertices_;
    }
    std::copy(tool_mm, tool_mm + axes_,
              tool_mm_.begin() + static_cast<std::ptrdiff_t>((k % tool_capacity_) * axes_));
    if (k >= ahead_) evaluate(k - ahead_);
}

void ContourErrorMeter::evaluate(std::uint64_t j) {
    const double* p = tool(j);
    double best = std::numeric_limits<double>::infinity();
    const auto consider = [&](const double* a, const double* b) {
        // The nearest point of segment a-b (b null: the point a).
        double ab_ab = 0, ap_ab = 0;
        if (b != nullptr) {
            for (std::size_t x = 0; x < axes_; ++x) {
                const double ab = b[x] - a[x];
                ab_ab += ab * ab;
                ap_ab += (p[x] - a[x]) * ab;
            }
        }
        const double t = ab_ab > 0 ? std::clamp(ap_ab / ab_ab, 0.0, 1.0) : 0.0;
        double squares = 0;
        double q[8];
        for (std::size_t x = 0; x < axes_; ++x) {
            q[x] = b != nullptr ? a[x] + t * (b[x] - a[x]) : a[x];
            const double d = p[x] - q[x];
            squares += d * d;
        }
        if (squares < best) {
            best = squares;
            std::copy(q, q + axes_, nearest_.begin());
        }
    };
    const std::uint64_t from = j > back_ ? j - back_ : 0;
    // From the newest vertex back to the one in effect at tick `from`: each vertex, and the
    // segment to the next one.
    for (std::uint64_t i = vertices_; i-- > 0;) {
        consider(vertex(i), nullptr);
        if (i + 1 < vertices_) consider(vertex(i), vertex(i + 1));
        if (vertex_tick(i) <= from) break;
    }
    const double distance = std::sqrt(best);
    sum_squares_ += best;
    if (r_.max_tool_mm.empty() || distance > r_.max_mm) {
        r_.max_mm = distance;
        r_.max_tick = j;
        r_.max_tool_mm.assign(p, p + axes_);
        r_.max_path_mm = nearest_;
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
