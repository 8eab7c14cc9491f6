// One piece of the path: the lookahead's backward pass, the whole-tick forward pass, and the
// local retries that lower the lookahead where the forward pass got stuck (docs/planner.md §5).
#include "piece.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>

#include "forward_pass.hpp"
#include "grid.hpp"
#include "jerk.hpp"
#include "limits.hpp"
#include "lookahead.hpp"
#include "lsb_rounding.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

WindowLookahead::WindowLookahead(const PathGrid& grid, const Limits& lim,
                                 const MachineProfile& prof, const PlanOptions& opt)
    : pg(grid), limits(lim), profile(prof), options(opt), end_zone(0.5 * prof.mm_per_lsb) {
    const std::size_t n = pg.grid.size();
    base_caps = speed_caps(pg, limits, profile, options);
    if (limits.has_jerk())
        jerk_caps(pg, limits, profile, jerk_setup(profile, limits).filter_ticks, base_caps);
    caps = base_caps;
    local_factor.assign(n, 1.0);
    local_cap.assign(n, 1.0);
    corner_factor.assign(n, 1.0);
    factor.assign(n, 1.0);
    beta.assign(n, 0.0);
    dip.assign(n, 0.0);
    reserve_for_corners(pg, limits, base_caps, profile, corner_factor);
    for (std::size_t k = 0; k < n; ++k) set_factor(k);
}

void WindowLookahead::set_factor(std::size_t k) {
    factor[k] = options.acceleration_margin * options.lookahead_bend_margin * local_factor[k] *
                corner_factor[k];
}

std::string where(const PathGrid& pg, const Piece& piece, double lambda, double run_offset) {
    const Run& run = pg.runs[piece.run];
    const double from = pg.grid.lambda[pg.pieces[run.pieces.front()].first];
    std::ostringstream m;
    m << (run.pen_down ? "subpath " : "travel to subpath ") << run.subpath << ", "
      << (lambda - from + run_offset) << " mm along it";
    return m.str();
}

PieceMotion plan_piece(WindowLookahead& la, const Piece& piece, const Vec& start_q,
                       PieceMotion* carried, double run_offset, PlanStats& st) {
    const PathGrid& pg = la.pg;
    const Grid& g = pg.grid;
    const PlanOptions& options = la.options;
    // Knots already sent (a piece continued from the last window): never replanned.
    const double floor =
        carried != nullptr && !carried->spans.empty() ? carried->spans.back().end.lambda : -1.0;
    const auto resume_at = [&](double lambda) {
        return std::max(lambda, floor + 1e-9 * (1 + std::fabs(floor)));
    };
    // The piece's regular span: longer than the window's where its feed is far below an LSB
    // per span (feed_span_ticks), as the forward pass takes it.
    const double span_time = feed_span_ticks(la.profile.ticks_per_span, piece.feed,
                                             la.profile.tick_hz, la.profile.mm_per_lsb) /
                             la.profile.tick_hz;
    backward_pass(pg, piece, la.limits, la.factor, options.lookahead_margin, la.caps, span_time,
                  la.end_zone, la.dip, la.beta);
    PieceMotion motion = forward_pass(pg, piece, la.limits, la.caps, la.beta, la.profile, options,
                                      start_q, carried, resume_at(g.lambda[piece.first]));
    // Retries are counted per place: a failure beyond the last one's window starts afresh
    // (the forward pass got further).
    int retry = 0;
    std::size_t site_end = 0, total_retries = 0;
    while (!motion.ok) {
        if (retry >= options.max_local_retries || ++total_retries > 100000) {
            throw PlanError(
                "cannot plan " + where(pg, piece, motion.fail_lambda, run_offset) +
                ": no whole-tick motion meets the limits there (limits too small for the geometry, "
                "or a degenerate curve)");
        }
        // Lower the lookahead's speed cap (every fourth retry also its acceleration budget)
        // around the place the forward pass got stuck, more widely with every retry, so that
        // it slows down earlier there; then resume the forward pass before the first node whose
        // lookahead changed. In the last third of the retries spans may also be shortened.
        const auto b = g.lambda.begin();
        std::size_t f = static_cast<std::size_t>(
            std::upper_bound(b + static_cast<std::ptrdiff_t>(piece.first),
                             b + static_cast<std::ptrdiff_t>(piece.last) + 1, motion.fail_lambda) -
            b);
        f = std::clamp<std::size_t>(f == 0 ? 0 : f - 1, piece.first, piece.last);
        if (f > site_end) retry = 0;
        const double fail_speed2 = motion.fail_speed * motion.fail_speed;
        const std::size_t w = static_cast<std::size_t>(retry / 2 + 1);
        // The whole piece is lowered only by the last two retries: a long piece without stops
        // (a polyline spiral is one) would otherwise cruise slower everywhere for one stubborn
        // corner, where more local retries succeed.
        const bool whole = retry >= options.max_local_retries - 2;
        const std::size_t from =
            whole ? piece.first : std::max(piece.first, f > 2 * w ? f - 2 * w : 0);
        std::size_t to = whole ? piece.last : std::min(piece.last, f + 8 * w);
        while (to < piece.last &&
               g.lambda[to] <= motion.fail_lambda + motion.fail_speed * span_time)
            ++to;
        for (std::size_t k = from; k <= to; ++k) {
            if (retry % 4 == 3) {
                la.local_factor[k] *= 0.9;
                la.set_factor(k);
            }
            // 4 % below the lookahead; and within one span ahead of the failure also 10 %
            // below the speed it failed at, so that the next attempt arrives slower.
            double x = 0.96 * la.beta[k];
            const double ahead = g.lambda[k] - motion.fail_lambda;
            if (ahead >= -1e-9 && ahead <= motion.fail_speed * span_time + 1e-9)
                x = std::min(x, 0.9 * fail_speed2);
            la.local_cap[k] = std::min(la.local_cap[k], x / std::max(la.base_caps[k], 1e-300));
            la.caps[k] = la.base_caps[k] * la.local_cap[k];
        }
        const std::size_t changed =
            backward_pass(pg, piece, la.limits, la.factor, options.lookahead_margin, la.caps,
                          span_time, la.end_zone, la.dip, la.beta, to + 1, from);
        const bool short_spans = retry >= 2 * options.max_local_retries / 3;
        // Knots in the interval ending at the first changed node interpolate its beta: resume
        // before that interval (never before what was sent).
        const std::size_t keep = changed > piece.first ? changed - 1 : piece.first;
        motion = forward_pass(pg, piece, la.limits, la.caps, la.beta, la.profile, options, start_q,
                              &motion, resume_at(g.lambda[keep]), short_spans);
        ++st.local_retries;
        site_end = std::max(site_end, to);
        ++retry;
    }
    return motion;
}

}  // namespace pathstream::host::planner_detail
