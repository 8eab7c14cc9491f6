// The jerk stage (jerk.cpp, docs/planner.md §12): its setup for a profile, why it failed,
// and the stage that retimes each piece so that every span meets the jerk limits exactly.
#pragma once

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <string>

#include "emit.hpp"
#include "forward_pass.hpp"
#include "grid.hpp"
#include "limits.hpp"
#include "pathstream/machine/machine.hpp"
#include "vec.hpp"

namespace pathstream::host::planner_detail {

/// Span length and filter of the jerk stage for a profile (docs/planner.md §12).
struct JerkSetup {
    bool active = false;
    std::uint32_t span_ticks = 0;             ///< ticks of every emitted motion span
    std::uint32_t filter_ticks = 0;           ///< M: the box filter's length
    std::array<double, kAxesMax> jerk_lsb{};  ///< LSB/tick^3 per axis (infinity: no limit)
};
/// The smallest span length >= `ticks` at which the jerk limits can be met exactly on the LSB
/// grid: J n^2 >= 8 and J n^3 >= 120 (J the smallest limit in LSB/tick^3).
std::uint32_t jerk_span_ticks(const MachineProfile& profile, std::uint32_t ticks);
/// The jerk stage's setup for `profile` (ticks_per_span already the regular one) and `limits`.
JerkSetup jerk_setup(const MachineProfile& profile, const Limits& limits);

/// Why the jerk stage could not emit a piece, for the replan of plan_stream.
struct JerkFailure {
    bool failed = false;
    bool velocity = false;  ///< a velocity limit (else jerk or acceleration)
    /// The rule that refused most candidates: 0 join, 1 jerk inside a span, 2 the end at
    /// rest, 3 acceleration, 4 velocity.
    int rule = 0;
    std::size_t axis = 0;
    std::string where;
};

/// The jerk stage (docs/planner.md §12): takes the second-order motion of each piece, span by
/// span, smooths its path parameter lambda(t) with a box filter of M ticks (the positions stay
/// on the path, only the timing changes), samples it every span_ticks ticks on the LSB grid and
/// chooses each knot's integer tangent so that every span's jerk and every join's
/// acceleration step are within the limits exactly. Streams: a piece cut between two windows
/// continues in the next one (rebase()).
class JerkStage {
public:
    JerkStage(const MachineProfile& profile, const JerkSetup& setup, std::size_t axes);
    /// A piece starts at rest at the emitter's position, at arc length `lambda`.
    void piece_begin(double lambda, std::size_t subpath, bool pen_down, const SpanEmitter& emitter);
    /// The second-order span from `from` to `span.end`; `pg`, `piece`: the current window's.
    /// Emits what is final. Returns false when no exact spans exist (failure() says where).
    bool raw_span(const Knot& from, const MotionSpan& span, const PathGrid& pg, const Piece& piece,
                  double run_offset, SpanEmitter& emitter);
    /// The piece's motion ended at rest (raw end point on the LSB grid: `end_q`); emits the rest.
    bool piece_end(const Vec& end_q, const PathGrid& pg, const Piece& piece, double run_offset,
                   SpanEmitter& emitter);
    /// A new window: arc length of the last raw knot there is `lambda` (the grids differ).
    void rebase(double lambda);
    const JerkFailure& failure() const { return failure_; }
    /// The extra ticks the filter and the rest at piece ends added (for the figures).
    std::uint64_t added_ticks() const { return added_ticks_; }

private:
    using LsbVec = std::array<std::int64_t, kAxesMax>;
    struct RawSpan {
        std::int64_t t0 = 0;
        std::uint32_t m = 0;
        double l0 = 0, l1 = 0, d0 = 0, d1 = 0;  ///< lambda at both ends, dlambda/du (mm per span)
    };
    struct JKnot {
        LsbVec p{};
        std::array<double, kAxesMax> target{};  ///< the C2 spline's tangent through the points
        LsbVec t{};
        double lambda = 0;
        std::array<Vec, 3> between{};    ///< the path at the quarters of the span ending here (mm)
        std::array<Vec, 3> between_t{};  ///< and its unit tangent there
    };
    static constexpr std::size_t kQuarters = 3;
    /// The whole tick nearest quarter i + 1 of a span (at least 1 tick apart from its ends).
    std::int64_t quarter_tick(std::size_t i) const {
        const std::int64_t n = setup_.span_ticks;
        return std::clamp<std::int64_t>((static_cast<std::int64_t>(i + 1) * n + 2) / 4,
                                        std::min<std::int64_t>(1, n - 1), n - 1);
    }
    void check_deviation(std::size_t k, const PathGrid& pg, const Piece& piece,
                         double run_offset) const;
    double filtered(std::int64_t t) const;
    double raw_lambda(double t) const;
    /// Positions of the knots up to raw time `until` (or all, once the piece ended).
    void add_knots(const PathGrid& pg, const Piece& piece);
    void add_targets();
    /// Chooses the tangents of knots chosen_from.. (backtracking), emits the final spans.
    bool choose_and_emit(bool end, const PathGrid& pg, const Piece& piece, double run_offset,
                         SpanEmitter& emitter);
    bool choose_axis(std::size_t axis, std::size_t from, std::size_t to, bool end);
    /// Whether knot k's tangent keeps the rules with the knots before it (see jerk.cpp).
    bool valid(std::size_t axis, std::size_t k, bool end) const;
    /// Counts a refusal by `rule` (for the failure's message); false.
    bool reject(int rule) const {
        ++rejected_[static_cast<std::size_t>(rule)];
        return false;
    }
    mutable std::array<std::size_t, 5> rejected_{};
    JKnot& knot(std::size_t k) { return knots_[k - knot_base_]; }
    const JKnot& knot(std::size_t k) const { return knots_[k - knot_base_]; }
    std::int64_t p_at(std::size_t axis, std::int64_t k) const;

    const MachineProfile& profile_;
    JerkSetup setup_;
    std::size_t axes_;
    std::array<double, kAxesMax> vlim_{}, alim_{};
    bool in_piece_ = false;
    std::size_t subpath_ = 0;
    bool pen_down_ = false;
    std::deque<RawSpan> raw_;
    std::int64_t raw_end_ = 0;
    double l_start_ = 0, l_end_ = 0;
    bool ended_ = false;
    std::size_t last_knot_ = 0;  ///< K, once ended
    std::deque<JKnot> knots_;
    std::size_t knot_base_ = 0;  ///< index of knots_.front()
    std::size_t targets_ = 0;    ///< knots with a target tangent
    std::size_t final_ = 0;      ///< knots whose tangent is final (spans up to it emitted)
    LsbVec p0_{}, end_p_{};      ///< the piece's start and end point (LSB)
    Vec end_q_{};                ///< the piece's end point (mm)
    LsbVec prev_a_{};            ///< the previous span's end acceleration (numerator)...
    std::uint32_t prev_n_ = 1;   ///< ...over this many ticks squared
    std::size_t hint_ = 0;
    JerkFailure failure_;
    std::uint64_t added_ticks_ = 0;
};

}  // namespace pathstream::host::planner_detail
