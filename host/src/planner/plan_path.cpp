// plan_path: grid -> lookahead -> whole-tick forward pass -> core spans -> per-tick check,
// re-planned with lowered limits if the check finds a tick over a limit.
#include <algorithm>
#include <cmath>
#include <sstream>

#include "internal.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {
namespace {

using namespace planner_detail;

void require(bool ok, const std::string& what) {
    if (!ok) throw PlanError("machine profile: " + what);
}

void validate(const MachineProfile& p, const PlanOptions& o) {
    require(!p.axes.empty() && p.axes.size() <= kAxesMax, "1 to 8 axes");
    for (const auto& a : p.axes) {
        require(std::isfinite(a.max_velocity) && a.max_velocity > 0, "axis " + a.name + ": max_velocity must be > 0");
        require(std::isfinite(a.max_acceleration) && a.max_acceleration > 0,
                "axis " + a.name + ": max_acceleration must be > 0");
    }
    require(std::isfinite(p.mm_per_lsb) && p.mm_per_lsb > 0, "mm_per_lsb must be > 0");
    require(std::isfinite(p.tick_hz) && p.tick_hz > 0, "tick_hz must be > 0");
    require(p.ticks_per_span >= 1 && p.ticks_per_span <= kMaxSpanTicks, "ticks_per_span must be 1..65536");
    require(std::isfinite(p.feed) && p.feed > 0, "feed must be > 0");
    require(std::isfinite(p.travel_feed) && p.travel_feed > 0, "travel_feed must be > 0");
    require(std::isfinite(p.chord_tolerance) && p.chord_tolerance > 0, "chord_tolerance must be > 0");
    require(std::isfinite(p.pen_down_delay) && p.pen_down_delay >= 0, "pen_down_delay must be >= 0");
    require(std::isfinite(p.pen_up_delay) && p.pen_up_delay >= 0, "pen_up_delay must be >= 0");
    if (!(o.velocity_margin > 0 && o.velocity_margin <= 1 && o.feed_margin > 0 && o.feed_margin <= 1 &&
          o.acceleration_margin > 0 && o.acceleration_margin <= 1 && o.lookahead_margin > 0 &&
          o.lookahead_margin <= 1 && o.lookahead_bend_margin > 0 && o.lookahead_bend_margin <= 1 && o.max_turn > 0 && o.min_nodes_per_segment >= 1)) {
        throw PlanError("plan options out of range");
    }
}

/// Non-decreasing progress in [0, 1], each stage mapped into its share.
class Progress {
public:
    explicit Progress(const std::function<void(double)>& f) : f_(f) {}
    void operator()(double fraction) {
        fraction = std::clamp(fraction, 0.0, 1.0);
        if (!f_ || fraction < last_) return;
        if (fraction < 1 && fraction - last_ < 0.002) return;  // no more than ~500 calls
        last_ = fraction;
        f_(fraction);
    }

private:
    const std::function<void(double)>& f_;
    double last_ = -1;
};

/// Ticks per regular span: the profile's, or more where its limits are fine against the LSB
/// grid. A span of n ticks has integer end points and tangents, so its end accelerations come
/// in steps of 2/n^2 to 6/n^2 LSB/tick^2 and its velocities in steps of 1/n LSB/tick. Spans
/// are lengthened until a n^2 >= 192 and v n >= 8 (a, v: the smallest limits in LSB/tick^2
/// and LSB/tick; 192 is the pen plotter's 3 LSB/tick^2 at 8 ticks): then the exact spans
/// nearest the planned ones lose about 1 % of the acceleration at most. With far fewer ticks
/// even starting from rest exactly within the limits can be impossible.
std::uint32_t span_ticks(const MachineProfile& p) {
    const double t = 1 / p.tick_hz;
    double n = p.ticks_per_span;
    for (const auto& a : p.axes) {
        n = std::max(n, std::ceil(std::sqrt(192 / (a.max_acceleration * t * t / p.mm_per_lsb)) - 1e-9));
        n = std::max(n, std::ceil(8 / (a.max_velocity * t / p.mm_per_lsb) - 1e-9));
    }
    return static_cast<std::uint32_t>(std::min<double>(n, kMaxSpanTicks));
}

std::string where(const PathGrid& g, const Piece& piece, double lambda) {
    const Run& run = g.runs[piece.run];
    const double from = g.grid.lambda[g.pieces[run.pieces.front()].first];
    std::ostringstream m;
    m << (run.pen_down ? "subpath " : "travel to subpath ") << run.subpath << ", " << (lambda - from)
      << " mm along it";
    return m.str();
}

}  // namespace

Plan plan_path(const std::vector<BezierSegment>& segments, const MachineProfile& profile,
               const std::function<void(double fraction)>& progress) {
    return plan_path(segments, profile, PlanOptions{}, nullptr, progress);
}

Plan plan_path(const std::vector<BezierSegment>& segments, const MachineProfile& machine_profile,
               const PlanOptions& options, PlanStats* stats, const std::function<void(double fraction)>& progress) {
    validate(machine_profile, options);
    MachineProfile profile = machine_profile;  // what is planned with: spans of span_ticks
    profile.ticks_per_span = span_ticks(machine_profile);
    Progress report(progress);
    PlanStats local;
    PlanStats& st = stats != nullptr ? *stats : local;
    st = PlanStats{};
    st.segments = segments.size();
    st.ticks_per_span = profile.ticks_per_span;
    report(0);
    if (segments.empty()) {
        report(1);
        return Plan{};
    }
    const PathGrid pg = build_grid(segments, profile, options);
    const Grid& g = pg.grid;
    st.grid_nodes = g.size();
    st.pieces = pg.pieces.size();
    report(0.05);

    Limits limits;
    for (const auto& a : profile.axes) {
        limits.velocity.push_back(a.max_velocity);
        limits.acceleration.push_back(a.max_acceleration);
    }
    double total = 0;
    for (const Piece& p : pg.pieces) total += g.lambda[p.last] - g.lambda[p.first];
    total = std::max(total, 1e-12);

    std::vector<double> local_factor(g.size(), 1.0), local_cap(g.size(), 1.0), factor(g.size()),
        beta(g.size(), 0.0), dip(g.size(), 0.0);
    const double span_time = profile.ticks_per_span / profile.tick_hz;
    double lo = 0.05, hi = 0.95;
    for (int attempt = 0;; ++attempt) {
        const std::vector<double> base_caps = speed_caps(pg, limits, profile, options);
        std::vector<double> caps = base_caps;
        for (std::size_t k = 0; k < g.size(); ++k) caps[k] *= local_cap[k];
        std::vector<double> corner_factor(g.size(), 1.0);
        reserve_for_corners(pg, limits, base_caps, span_time, corner_factor);
        const auto set_factor = [&](std::size_t k) {
            factor[k] = options.acceleration_margin * options.lookahead_bend_margin * local_factor[k] * corner_factor[k];
        };
        for (std::size_t k = 0; k < g.size(); ++k) set_factor(k);
        std::vector<PieceMotion> motion(pg.pieces.size());
        double done = 0;
        // Pieces chain on the LSB grid: each starts exactly where the previous one ended.
        Vec start_q = on_lsb_grid(pg.runs.front().start, profile.mm_per_lsb, g.axes);
        for (std::size_t p = 0; p < pg.pieces.size(); ++p) {
            const Piece& piece = pg.pieces[p];
            backward_pass(pg, piece, limits, factor, options.lookahead_margin, caps, span_time, dip, beta);
            motion[p] = forward_pass(pg, piece, limits, caps, beta, profile, options, start_q);
            // Retries are counted per place: a failure beyond the last one's window starts
            // afresh (the forward pass got further).
            int retry = 0;
            std::size_t site_end = 0, total_retries = 0;
            while (!motion[p].ok) {
                if (retry >= options.max_local_retries || ++total_retries > 100000) {
                    throw PlanError("cannot plan " + where(pg, piece, motion[p].fail_lambda) +
                                    ": no whole-tick motion meets the limits there (limits too small "
                                    "for the geometry, or a degenerate curve)");
                }
                // Lower the lookahead's speed cap (every fourth retry also its acceleration
                // budget) around the place the forward pass got stuck, more widely with every
                // retry, so that it slows down earlier there; then resume the forward pass
                // before the first node whose lookahead changed. In the last third of the
                // retries spans may also be shortened.
                const auto b = g.lambda.begin();
                std::size_t f = static_cast<std::size_t>(
                    std::upper_bound(b + static_cast<std::ptrdiff_t>(piece.first),
                                     b + static_cast<std::ptrdiff_t>(piece.last) + 1, motion[p].fail_lambda) - b);
                f = std::clamp<std::size_t>(f == 0 ? 0 : f - 1, piece.first, piece.last);
                if (f > site_end) retry = 0;
                const double fail_speed2 = motion[p].fail_speed * motion[p].fail_speed;
                const std::size_t w = static_cast<std::size_t>(retry / 2 + 1);
                const bool whole = retry >= options.max_local_retries / 2;
                const std::size_t from = whole ? piece.first : std::max(piece.first, f > 2 * w ? f - 2 * w : 0);
                std::size_t to = whole ? piece.last : std::min(piece.last, f + 8 * w);
                while (to < piece.last && g.lambda[to] <= motion[p].fail_lambda + motion[p].fail_speed * span_time) ++to;
                for (std::size_t k = from; k <= to; ++k) {
                    if (retry % 4 == 3) {
                        local_factor[k] *= 0.9;
                        set_factor(k);
                    }
                    // 4 % below the lookahead; and within one span ahead of the failure also
                    // 10 % below the speed it failed at, so that the next attempt arrives slower.
                    double x = 0.96 * beta[k];
                    const double ahead = g.lambda[k] - motion[p].fail_lambda;
                    if (ahead >= -1e-9 && ahead <= motion[p].fail_speed * span_time + 1e-9) {
                        x = std::min(x, 0.9 * fail_speed2);
                    }
                    local_cap[k] = std::min(local_cap[k], x / std::max(base_caps[k], 1e-300));
                    caps[k] = base_caps[k] * local_cap[k];
                }
                const std::size_t changed =
                    backward_pass(pg, piece, limits, factor, options.lookahead_margin, caps, span_time, dip, beta,
                                  to + 1, from);
                const bool short_spans = retry >= 2 * options.max_local_retries / 3;
                PieceMotion previous = std::move(motion[p]);
                // Knots in the interval ending at the first changed node interpolate its beta:
                // resume before that interval.
                const std::size_t keep = changed > piece.first ? changed - 1 : piece.first;
                motion[p] = forward_pass(pg, piece, limits, caps, beta, profile, options, start_q, &previous,
                                         g.lambda[keep], short_spans);
                ++st.local_retries;
                site_end = std::max(site_end, to);
                ++retry;
            }
            start_q = motion[p].spans.empty() ? motion[p].start.q : motion[p].spans.back().end.q;
            done += g.lambda[piece.last] - g.lambda[piece.first];
            report(lo + (hi - lo) * 0.85 * done / total);
        }
        Plan plan = emit_plan(pg, motion, profile, &st);
        const PlanCheck check = check_plan_impl(plan, segments, profile, false);
        report(hi);
        if (check.drawing_while_pen_moves) throw PlanError("internal: the plan moves during a pen dwell");
        if (check.within_limits) {
            if (stats != nullptr) {  // the continuous optimum with the full limits, same grid
                PlanOptions full = options;
                full.velocity_margin = full.feed_margin = 1;
                Limits machine;
                for (const auto& a : profile.axes) {
                    machine.velocity.push_back(a.max_velocity);
                    machine.acceleration.push_back(a.max_acceleration);
                }
                const std::vector<double> full_caps = speed_caps(pg, machine, profile, full);
                const std::vector<double> ones(g.size(), 1.0);
                double t = 0;
                for (const Piece& piece : pg.pieces) {
                    backward_pass(pg, piece, machine, ones, 1.0, full_caps, 0.0, dip, beta);
                    t += topp_piece_time(pg, piece, machine, ones, beta);
                }
                st.reference_motion_time = t;
            }
            report(1);
            return plan;
        }
        if (attempt >= options.max_replans) {
            std::ostringstream m;
            m << "cannot meet the machine's limits on every tick after " << attempt
              << " replans (velocity at " << 100 * check.max_velocity_fraction << " %, acceleration at "
              << 100 * check.max_acceleration_fraction << " % of the limit after the rounding allowance; the "
              << "exact cubic at " << 100 * std::max(check.max_velocity_fraction_exact, check.max_span_velocity_fraction)
              << " % and " << 100 * std::max(check.max_acceleration_fraction_exact, check.max_span_acceleration_fraction)
              << " %)";
            throw PlanError(m.str());
        }
        for (std::size_t i = 0; i < profile.axes.size(); ++i) {
            const double fv = std::max(check.axis_velocity_fraction[i], check.axis_velocity_fraction_exact[i]);
            const double fa = std::max(check.axis_acceleration_fraction[i], check.axis_acceleration_fraction_exact[i]);
            if (fv > 1) limits.velocity[i] *= 0.99 / fv;
            if (fa > 1) limits.acceleration[i] *= 0.99 / fa;
            st.velocity_scale = std::min(st.velocity_scale, limits.velocity[i] / profile.axes[i].max_velocity);
            st.acceleration_scale =
                std::min(st.acceleration_scale, limits.acceleration[i] / profile.axes[i].max_acceleration);
        }
        ++st.replans;
        lo = hi;
        hi = lo + (0.99 - lo) * 0.8;
    }
}

}  // namespace pathstream::host
