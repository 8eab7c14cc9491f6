#include "pathstream/host/job_estimate.hpp"

#include <algorithm>
#include <cmath>

#include "pathstream/host/segment_source.hpp"

namespace pathstream::host {
namespace {

double distance(const PathPoint& a, const PathPoint& b) {
    double sum = 0;
    for (std::size_t i = 0; i < a.size() && i < b.size(); ++i) sum += (a[i] - b[i]) * (a[i] - b[i]);
    return std::sqrt(sum);
}

// A Bezier's length lies between its chord and its control polygon; their mean is close.
double segment_length(const BezierSegment& s) {
    const double chord = distance(s.p[0], s.p[3]);
    const double polygon =
        distance(s.p[0], s.p[1]) + distance(s.p[1], s.p[2]) + distance(s.p[2], s.p[3]);
    return 0.5 * (chord + polygon);
}

// The fastest the axes allow along the chord of `s` (each axis's share of the speed), and
// the slowest acceleration among the axes that move.
struct AxisCaps {
    double velocity;
    double acceleration;
};
AxisCaps axis_caps(const BezierSegment& s, const MachineProfile& profile) {
    const double chord = distance(s.p[0], s.p[3]);
    AxisCaps caps{1e300, 1e300};
    for (std::size_t a = 0; a < profile.axes.size() && a < s.p[0].size(); ++a) {
        const double share = chord > 0 ? std::abs(s.p[3][a] - s.p[0][a]) / chord : 1.0;
        if (share > 1e-9)
            caps.velocity = std::min(caps.velocity, profile.axes[a].max_velocity / share);
        caps.acceleration = std::min(caps.acceleration, profile.axes[a].max_acceleration);
    }
    return caps;
}

}  // namespace

JobEstimate::JobEstimate(const std::vector<BezierSegment>& segments, const MachineProfile& profile)
    : tick_hz_(profile.tick_hz) {
    VectorSegmentSource source(segments);
    add(source, profile);
}

JobEstimate::JobEstimate(SegmentSource& source, const MachineProfile& profile)
    : tick_hz_(profile.tick_hz) {
    add(source, profile);
    source.rewind();
}

void JobEstimate::add(SegmentSource& source, const MachineProfile& profile) {
    length_.reserve(source.size_hint() + 1);
    seconds_.reserve(source.size_hint() + 1);
    length_.push_back(0);
    seconds_.push_back(0);
    BezierSegment s;
    bool first = true, previous_pen_down = false;
    while (source.next(s)) {
        const double feed = s.feed > 0 ? s.feed : (s.pen_down ? profile.feed : profile.travel_feed);
        const AxisCaps caps = axis_caps(s, profile);
        const double v = std::max(1e-6, std::min(feed, caps.velocity));
        const double mm = segment_length(s);
        double t = mm / v + s.dwell_before;
        // Rest at the start of this segment: a stop before it and a start after (each v / 2a
        // longer than at full speed).
        const bool rest = first || s.pen_down != previous_pen_down || s.pause_before ||
                          s.stop_before || s.dwell_before > 0;
        if (rest && caps.acceleration > 0) t += v / caps.acceleration;
        length_.push_back(length_.back() + mm);
        seconds_.push_back(seconds_.back() + t);
        first = false;
        previous_pen_down = s.pen_down;
    }
}

std::uint64_t JobEstimate::total_ticks(double planned_mm, std::uint64_t planned_ticks) const {
    const double total = seconds_.back();
    const double planned_s = static_cast<double>(planned_ticks) / tick_hz_;
    if (planned_ticks == 0 || planned_mm <= 0)
        return static_cast<std::uint64_t>(std::llround(total * tick_hz_));
    // The model's seconds at `planned_mm` along the path.
    const double at = std::min(planned_mm, length_.back());
    const auto upper = std::upper_bound(length_.begin(), length_.end(), at);
    const std::size_t k = upper == length_.end()
                              ? length_.size() - 1
                              : static_cast<std::size_t>(upper - length_.begin());
    double model_at = seconds_[k];
    if (k > 0 && length_[k] > length_[k - 1]) {
        const double u = (at - length_[k - 1]) / (length_[k] - length_[k - 1]);
        model_at = seconds_[k - 1] + u * (seconds_[k] - seconds_[k - 1]);
    }
    // The planner's slow-downs seen so far apply to the rest; bounded while the planned part
    // is too short to say much.
    const double scale = model_at > 0 ? std::clamp(planned_s / model_at, 0.25, 8.0) : 1.0;
    const double rest = std::max(0.0, total - model_at) * scale;
    return planned_ticks + static_cast<std::uint64_t>(std::llround(rest * tick_hz_));
}

}  // namespace pathstream::host
