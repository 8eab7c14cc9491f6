// plan_path: plan_stream into a Plan held in memory, and the continuous optimum for PlanStats.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "corner_blend.hpp"
#include "grid.hpp"
#include "limits.hpp"
#include "lookahead.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/core_span.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/units.hpp"
#include "plan_inputs.hpp"
#include "vec.hpp"

namespace pathstream::host {
namespace {

using namespace planner_detail;

void require(bool ok, const std::string& what) {
    if (!ok) throw PlanError("machine profile: " + what);
}

}  // namespace

namespace planner_detail {

PlanOptions profile_options(const PlanOptions& options, const MachineProfile& profile) {
    PlanOptions out = options;
    if (profile.corner_stop_angle >= 0) out.corner_stop_angle = profile.corner_stop_angle;
    return out;
}

void validate_plan_inputs(const MachineProfile& p, const PlanOptions& o) {
    require(!p.axes.empty() && p.axes.size() <= kAxesMax, "1 to 8 axes");
    for (const auto& a : p.axes) {
        require(std::isfinite(a.max_velocity) && a.max_velocity > 0,
                "axis " + a.name + ": max_velocity must be > 0");
        require(std::isfinite(a.max_acceleration) && a.max_acceleration > 0,
                "axis " + a.name + ": max_acceleration must be > 0");
    }
    require(std::isfinite(p.mm_per_lsb) && p.mm_per_lsb > 0, "mm_per_lsb must be > 0");
    require(std::isfinite(p.tick_hz) && p.tick_hz > 0, "tick_hz must be > 0");
    require(p.ticks_per_span >= 1 && p.ticks_per_span <= kMaxSpanTicks,
            "ticks_per_span must be 1..65536");
    require(std::isfinite(p.feed) && p.feed > 0, "feed must be > 0");
    require(std::isfinite(p.travel_feed) && p.travel_feed > 0, "travel_feed must be > 0");
    require(std::isfinite(p.chord_tolerance) && p.chord_tolerance > 0,
            "chord_tolerance must be > 0");
    require(std::isfinite(p.pen_down_delay) && p.pen_down_delay >= 0,
            "pen_down_delay must be >= 0");
    require(std::isfinite(p.pen_up_delay) && p.pen_up_delay >= 0, "pen_up_delay must be >= 0");
    // A jerk limit needs spans of n ticks with J n^2 >= 8 and J n^3 >= 120 (J in LSB/tick^3,
    // docs/planner.md §12); spans beyond 8 times the regular length are refused.
    const double tick = 1 / p.tick_hz;
    const double n_max = std::min<double>(8.0 * regular_span_ticks(p), kMaxSpanTicks);
    const double j_min = std::max(8 / (n_max * n_max), 120 / (n_max * n_max * n_max)) *
                         p.mm_per_lsb / (tick * tick * tick);
    for (const auto& a : p.axes) {
        require(std::isfinite(a.max_jerk) && a.max_jerk >= 0,
                "axis " + a.name + ": max_jerk must be >= 0");
        if (a.max_jerk > 0 && a.max_jerk < j_min) {
            std::ostringstream m;
            m << (p.source.empty() ? "" : p.source + ": ") << "axis " << a.name << ": max_jerk "
              << a.max_jerk << " mm/s^3 is below the planner's minimum of " << j_min
              << " mm/s^3 for this profile (spans of at most " << n_max
              << " ticks must meet it exactly on the LSB grid; use a larger max_jerk or "
                 "mm_per_lsb)";
            throw PlanError("machine profile: " + m.str());
        }
    }
    if (!(o.velocity_margin > 0 && o.velocity_margin <= 1 && o.feed_margin > 0 &&
          o.feed_margin <= 1 && o.acceleration_margin > 0 && o.acceleration_margin <= 1 &&
          o.lookahead_margin > 0 && o.lookahead_margin <= 1 && o.lookahead_bend_margin > 0 &&
          o.lookahead_bend_margin <= 1 && o.max_turn > 0 && o.min_nodes_per_segment >= 1)) {
        throw PlanError("plan options out of range");
    }
}

/// Ticks per regular span: the profile's, or more where its limits are fine against the LSB
/// grid. A span of n ticks has integer end points and tangents, so its end accelerations come
/// in steps of 2/n^2 to 6/n^2 LSB/tick^2 and its velocities in steps of 1/n LSB/tick. Spans
/// are lengthened until a n^2 >= 192 and v n >= 8 (a, v: the smallest limits in LSB/tick^2
/// and LSB/tick; 192 is the pen plotter's 3 LSB/tick^2 at 8 ticks): then the exact spans
/// nearest the planned ones lose about 1 % of the acceleration at most. With far fewer ticks
/// even starting from rest exactly within the limits can be impossible.
std::uint32_t regular_span_ticks(const MachineProfile& p) {
    const double t = 1 / p.tick_hz;
    double n = p.ticks_per_span;
    for (const auto& a : p.axes) {
        n = std::max(
            n, std::ceil(std::sqrt(192 / (a.max_acceleration * t * t / p.mm_per_lsb)) - 1e-9));
        n = std::max(n, std::ceil(8 / (a.max_velocity * t / p.mm_per_lsb) - 1e-9));
    }
    return static_cast<std::uint32_t>(std::min<double>(n, kMaxSpanTicks));
}

}  // namespace planner_detail

namespace {

/// Collects a streamed plan into a Plan (a replan starts it afresh).
class PlanCollector : public PlanSink {
public:
    void span(const CoreSpan& s) override {
        plan.spans.push_back(s);
        plan.total_ticks += s.ticks;
    }
    void pen(const PenEvent& e) override { plan.pen.push_back(e); }
    void pause(const PlanPause& p) override { plan.pauses.push_back(p); }
    bool restart() override {
        plan = Plan{};
        return true;
    }
    Plan plan;
};

}  // namespace

Plan plan_path(const std::vector<BezierSegment>& segments, const MachineProfile& profile,
               const std::function<void(double fraction)>& progress) {
    return plan_path(segments, profile, PlanOptions{}, nullptr, progress);
}

Plan plan_path(const std::vector<BezierSegment>& segments, const MachineProfile& machine_profile,
               const PlanOptions& options, PlanStats* stats,
               const std::function<void(double fraction)>& progress) {
    VectorSegmentSource source(segments);
    PlanCollector out;
    const PlanTotals totals = plan_stream(source, machine_profile, options, out, stats, progress);
    Plan plan = std::move(out.plan);
    plan.total_ticks = totals.total_ticks;
    plan.duration = totals.duration;
    plan.path_length = totals.path_length;
    plan.travel_length = totals.travel_length;
    if (stats != nullptr && !segments.empty()) {
        // The continuous optimum with the full limits on the whole path's grid (held in memory
        // for this figure only).
        MachineProfile profile = machine_profile;
        profile.ticks_per_span = regular_span_ticks(machine_profile);
        // On the path as planned: corners blended as plan_stream blends them.
        std::vector<BezierSegment> planned;
        VectorSegmentSource again(segments);
        const PlanOptions planned_options = profile_options(options, profile);
        CornerBlender blended(again, options.corner_blend * profile.chord_tolerance,
                              planned_options.corner_stop_angle);
        SegmentSource& input =
            options.corner_blend > 0 ? static_cast<SegmentSource&>(blended) : again;
        for (BezierSegment s; input.next(s);) planned.push_back(s);
        const PathGrid pg = build_grid(planned, profile, planned_options);
        PlanOptions full = options;
        full.velocity_margin = full.feed_margin = 1;
        Limits machine;
        for (const auto& a : profile.axes) {
            machine.velocity.push_back(a.max_velocity);
            machine.acceleration.push_back(a.max_acceleration);
        }
        const std::vector<double> full_caps = speed_caps(pg, machine, profile, full);
        const std::vector<double> ones(pg.grid.size(), 1.0);
        std::vector<double> beta(pg.grid.size(), 0.0), dip(pg.grid.size(), 0.0);
        double t = 0;
        for (const Piece& piece : pg.pieces) {
            backward_pass(pg, piece, machine, ones, 1.0, full_caps, 0.0, 0.0, dip, beta);
            t += topp_piece_time(pg, piece, machine, ones, beta);
        }
        stats->reference_motion_time = t;
        stats->segments = segments.size();
    }
    return plan;
}

}  // namespace pathstream::host
