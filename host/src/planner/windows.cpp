// plan_stream: the path planned in windows of segments with a bounded lookahead, each window's
// spans checked tick by tick and handed on, so that memory does not grow with the job
// (docs/planner.md §8).
//
// A window is planned like a whole path whose end is a stop. Only the motion up to the commit
// point, a horizon (more than the longest stopping distance) before the window's end, is
// kept: there the lookahead already sees as far as it ever would. The next window starts at
// the segment holding the last kept knot and continues from that knot (the retries never go
// back before it). Window N's per-tick check runs on a second thread while window N + 1 is
// planned; window N goes to the sink once its check passed.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "check.hpp"
#include "corner_blend.hpp"
#include "cubic.hpp"
#include "emit.hpp"
#include "forward_pass.hpp"
#include "grid.hpp"
#include "jerk.hpp"
#include "jerk_meter.hpp"
#include "limits.hpp"
#include "lsb_rounding.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/handoff_worker.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "piece.hpp"
#include "plan_inputs.hpp"
#include "vec.hpp"

namespace pathstream::host {
namespace {

using namespace planner_detail;

constexpr std::size_t kMaxWindowSegments = std::size_t{1} << 26;

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

/// Where the kept motion ended: the knot it reached inside a segment (λ from that segment's
/// start) and the knot the last span started from, or a piece start at rest.
struct Carry {
    bool started = false;     ///< anything planned yet
    std::size_t segment = 0;  ///< global index of the segment holding the knot
    double lambda_in_segment = 0;
    bool moving = false;      ///< mid-piece: continue from `last` (else a piece starts at rest)
    Knot prev, last;          ///< the last span ran from prev to last...
    std::uint32_t ticks = 0;  ///< ...in this many ticks
    Vec q{};                  ///< where the motion is (mm, on the LSB grid)
    double run_offset = 0;    ///< mm of the current run before `segment`
};

/// A segment's requested feed, as the per-tick check needs it for the segment's spans.
struct FeedNote {
    std::size_t subpath = 0;
    bool pen_down = false;
    double feed = 0;
};

/// A window's events on their way through the per-tick check, with the feeds of the segments
/// read since the batch before.
struct CheckBatch {
    std::vector<PlanEvent> events;
    std::vector<FeedNote> feeds;
};

/// One attempt at the whole job with fixed limits.
class WindowPlanner {
public:
    WindowPlanner(SegmentSource& source, const MachineProfile& profile, const PlanOptions& options,
                  const Limits& limits, PlanSink& sink, PlanStats& stats, Progress& report,
                  double lo, double hi, SegmentSource* check_path)
        : source_(source),
          profile_(profile),
          options_(options),
          limits_(limits),
          sink_(sink),
          st_(stats),
          report_(report),
          lo_(lo),
          hi_(hi),
          checker_(check_path != nullptr ? std::make_unique<TickChecker>(profile, *check_path)
                                         : std::make_unique<TickChecker>(profile, nullptr, false)),
          jerk_meter_(profile),
          check_([this](const CheckBatch& batch) { return check_batch(batch); },
                 options.check_on_thread && std::thread::hardware_concurrency() > 1
                     ? HandoffWorker<CheckBatch>::Mode::kThread
                     : HandoffWorker<CheckBatch>::Mode::kCaller) {
        double a_min = std::numeric_limits<double>::infinity(), v_axes = 0;
        for (std::size_t i = 0; i < profile.axes.size(); ++i) {
            a_min = std::min(a_min, limits.acceleration[i]);
            v_axes += limits.velocity[i] * limits.velocity[i];
        }
        a_min_ = a_min;
        v_axes_ = std::sqrt(v_axes);
        top_speed_ = std::min(v_axes_, std::max(profile.feed, profile.travel_feed));
        total_ = source.size_hint();
        jerk_setup_ = jerk_setup(profile, limits);
    }

    /// Where the jerk stage could not meet the limits (failed: a replan with less acceleration).
    const JerkFailure& jerk_failure() const { return jerk_failure_; }
    std::uint32_t jerk_filter_ticks() const { return jerk_setup_.filter_ticks; }
    std::uint64_t jerk_added_ticks() const { return jerk_ ? jerk_->added_ticks() : 0; }

    /// Plans the job; false when the per-tick check found a tick over a limit (`check` says
    /// which), true when every span went to the sink.
    bool run(PlanCheck& check, PlanTotals& totals) {
        std::size_t want = window_segments();
        for (;;) {
            read(want);
            if (buffer_.empty()) break;  // nothing at all
            const std::size_t window_first = window_start();
            buffer_.erase(buffer_.begin(),
                          buffer_.begin() + static_cast<std::ptrdiff_t>(window_first - base_));
            nominal_.erase(nominal_.begin(),
                           nominal_.begin() + static_cast<std::ptrdiff_t>(window_first - base_));
            base_ = window_first;
            const PathGrid pg = build_grid(buffer_, profile_, options_, base_);
            const double end = pg.grid.size() > 0 ? pg.grid.lambda.back() : 0.0;
            const double carry_lambda = carry_in(pg);
            double commit = std::numeric_limits<double>::infinity();
            if (!exhausted_) {
                commit = end - horizon();
                // Room for at least a couple of spans past the carry, else read more.
                const double room = 2 * v_axes_ * profile_.ticks_per_span / profile_.tick_hz + 1e-3;
                if (!(commit > carry_lambda + room) && want < kMaxWindowSegments) {
                    want *= 2;
                    continue;
                }
                commit = std::max(commit, carry_lambda);
            }
            const auto before = std::pair{carry_.segment, carry_.lambda_in_segment};
            plan_window(pg, carry_lambda, commit);
            if (jerk_failure_.failed) return fail(check);
            st_.grid_nodes += pg.grid.size();
            if (exhausted_ && !cut_) {
                emitter().finish(last_subpath_);
                if (!deliver()) return fail(check);
                break;
            }
            if (!deliver()) return fail(check);
            if (std::pair{carry_.segment, carry_.lambda_in_segment} == before) {
                // No span fitted before the commit point: a longer window moves it further.
                if (want >= kMaxWindowSegments)
                    throw PlanError("internal: the windowed planner made no progress");
                want *= 2;
            } else {
                want = window_segments();
            }
            if (total_ > 0)
                report_(lo_ + (hi_ - lo_) * static_cast<double>(carry_.segment) /
                                  static_cast<double>(total_));
        }
        if (!collect_checked()) return fail(check);
        check = checker_->finish();
        jerk_meter_.finish(check);
        if (!check.within_limits) return false;
        totals.spans = spans_;
        totals.pen_changes = pens_;
        totals.pauses = pauses_;
        totals.total_ticks = emitter_ ? emitter_->total_ticks() : 0;
        totals.duration = static_cast<double>(totals.total_ticks) / profile_.tick_hz;
        totals.path_length = pen_down_length_;
        totals.travel_length = travel_length_;
        if (emitter_) {
            st_.motion_spans = emitter_->motion_spans();
            st_.motion_ticks = emitter_->motion_ticks();
            st_.dwell_ticks = emitter_->dwell_ticks();
        }
        return true;
    }

    /// Whether any event went to the sink.
    bool sent() const { return spans_ + pens_ + pauses_ > 0; }

private:
    SpanEmitter& emitter() { return *emitter_; }
    std::size_t window_segments() const {
        return std::clamp<std::size_t>(options_.window_segments, 16, kMaxWindowSegments);
    }

    /// The check's figures after a failed window; a window still in the check (the one before
    /// a failed jerk stage) is first finished and, if it passed, sent as it would have been.
    bool fail(PlanCheck& check) {
        (void)collect_checked();
        check = checker_->finish();
        return false;
    }

    /// Reads until `want` segments lie at or after the carry's segment, or they would take
    /// about window_ticks (times want over the usual count) at their feeds, or the path ends:
    /// a slow job's window holds a bounded number of spans, not hours of them.
    void read(std::size_t want) {
        const double tick_cap =
            static_cast<double>(std::max<std::uint64_t>(options_.window_ticks, 1000)) *
            static_cast<double>(want) / static_cast<double>(window_segments());
        double ticks = 0;
        for (std::size_t i = carry_.segment - base_; i < nominal_.size(); ++i) ticks += nominal_[i];
        while (!exhausted_ && buffer_.size() - (carry_.segment - base_) < want &&
               ticks < tick_cap) {
            BezierSegment s;
            if (!source_.next(s)) {
                exhausted_ = true;
                break;
            }
            const double length = segment_length(s);
            account(s, length);
            nominal_.push_back(nominal_ticks(s, length));
            ticks += nominal_.back();
            next_.feeds.push_back({s.subpath, s.pen_down, s.feed});
            top_speed_ = std::max(top_speed_, std::min(v_axes_, s.feed));
            buffer_.push_back(std::move(s));
        }
    }

    /// Ticks a segment of `length` mm takes at its feed (at most the axes' combined speed), not
    /// counting speed changes: enough to bound a window's length in time.
    double nominal_ticks(const BezierSegment& s, double length) const {
        const double feed =
            s.feed > 0 ? s.feed : (s.pen_down ? profile_.feed : profile_.travel_feed);
        const double speed = std::min(v_axes_, feed);
        return speed > 0 ? length / speed * profile_.tick_hz : 0.0;
    }

    /// Arc length of a segment, mm (0 for a degenerate one or one with the wrong axis count).
    double segment_length(const BezierSegment& s) const {
        if (s.p[0].size() != profile_.axes.size()) return 0;  // build_grid reports it
        const Cubic c = to_cubic(s);
        if (c.size() < 1e-9) return 0;
        const double length = arc_length(c, 0, 0.5) + arc_length(c, 0.5, 1);
        return length >= 1e-9 ? length : 0.0;
    }

    /// The pen-down and travel length of a new segment, `length` mm (degenerate ones: 0).
    void account(const BezierSegment& s, double length) {
        if (length <= 0) return;
        (s.pen_down ? pen_down_length_ : travel_length_) += length;
        last_subpath_ = s.subpath;
    }

    /// Global index of the window's first segment: the carry's, or the one before it when
    /// the motion continues across their joint (so the joint is planned as before).
    std::size_t window_start() const {
        std::size_t first = carry_.segment;
        if (carry_.moving && first > base_) {
            const BezierSegment& a = buffer_[first - 1 - base_];
            const BezierSegment& b = buffer_[first - base_];
            if (a.pen_down == b.pen_down && a.subpath == b.subpath) --first;
        }
        if (carry_.moving && jerk_setup_.active) {
            // The jerk stage's filtered position lags the motion by up to M ticks of travel:
            // the path there must be in this window too.
            const double lag = (jerk_setup_.filter_ticks + 2.0 * profile_.ticks_per_span) /
                                   profile_.tick_hz * top_speed_ +
                               1.0 + carry_.lambda_in_segment;
            double back = 0;
            while (first > base_ && back < lag) {
                const BezierSegment& a = buffer_[first - 1 - base_];
                const BezierSegment& b = buffer_[first - base_];
                if (a.pen_down != b.pen_down || a.subpath != b.subpath) break;
                const Cubic c = to_cubic(a);
                back += arc_length(c, 0, 0.5) + arc_length(c, 0.5, 1);
                --first;
            }
        }
        return first;
    }

    /// The carry's arc length in this window's grid.
    double carry_in(const PathGrid& pg) const {
        if (!carry_.started) return 0;
        const std::size_t k = carry_node(pg);
        const bool inside = k < pg.grid.size() && pg.grid.seg[k] == carry_.segment - base_;
        return segment_start(pg) + (inside ? carry_.lambda_in_segment : 0.0);
    }

    /// The first node of the carry's segment in this grid (or of the first segment after it;
    /// the grid's size when there is none).
    std::size_t carry_node(const PathGrid& pg) const {
        const Grid& g = pg.grid;
        const std::size_t local = carry_.segment - base_;
        std::size_t k = 0;
        while (k < g.size() && g.seg[k] < local) ++k;
        return k;
    }

    /// The longest stopping distance plus a margin: beyond it the lookahead sees as far as it
    /// would on the whole path (the lookahead plans speed changes with part of the budget,
    /// less near corners, hence twice the plain v^2 / 2a).
    double horizon() const {
        const double span = profile_.ticks_per_span / profile_.tick_hz;
        return 1.1 * top_speed_ * top_speed_ / a_min_ + 4 * top_speed_ * span + 1.0;
    }

    void plan_window(const PathGrid& pg, double carry_lambda, double commit) {
        const Grid& g = pg.grid;
        WindowLookahead la(pg, limits_, profile_, options_);
        cut_ = false;
        if (!emitter_) {
            emitter_.emplace(profile_, g.axes, pg.runs.front().start);
            if (jerk_setup_.active) {
                emitter_->set_jerk_limits(jerk_setup_.jerk_lsb);
                jerk_.emplace(profile_, jerk_setup_, g.axes);
            }
            carry_.q = on_lsb_grid(pg.runs.front().start, profile_.mm_per_lsb, g.axes);
            carry_.started = true;
        }
        bool carried_used = false;
        for (std::size_t r = 0; r < pg.runs.size() && !cut_; ++r) {
            const Run& run = pg.runs[r];
            // Messages measure along the whole run: a run continued from the last window
            // started before this grid.
            const double run_start = g.lambda[pg.pieces[run.pieces.front()].first];
            const double run_offset =
                r == 0 && carry_.moving ? carry_.run_offset - (segment_start(pg) - run_start) : 0.0;
            for (const std::size_t index : run.pieces) {
                const Piece& piece = pg.pieces[index];
                const double first = g.lambda[piece.first], last = g.lambda[piece.last];
                // Done already: wholly before the carry (a piece at rest at the carry's point
                // starts there, and zero-length pieces before it were sent).
                if (last < carry_lambda - 1e-9 || (last <= carry_lambda + 1e-12 && first < last))
                    continue;
                if (first < carry_lambda - 1e-9 && !carry_.moving) continue;
                emitter().begin_run(run);
                PieceMotion carried;
                const bool resume = carry_.moving && !carried_used &&
                                    first <= carry_lambda + 1e-9 && carry_lambda < last;
                if (resume) {
                    carried.start.lambda = first;
                    carried.start.q = carry_.q;
                    MotionSpan a{0, carry_.prev}, b{carry_.ticks, carry_.last};
                    a.end.lambda = std::min(carry_lambda, std::max(first, carry_lambda - 1e-9));
                    b.end.lambda = carry_lambda;
                    carried.spans = {a, b};
                    carried_used = true;
                } else {
                    emitter().piece_start(carry_.q, run.subpath);
                }
                if (jerk_) {
                    if (resume)
                        jerk_->rebase(carry_lambda);
                    else
                        jerk_->piece_begin(first, run.subpath, run.pen_down, emitter());
                }
                PieceMotion m =
                    plan_piece(la, piece, carry_.q, resume ? &carried : nullptr, run_offset, st_);
                ++st_.pieces;
                const std::size_t skip = resume ? 2 : 0;
                Knot from = skip > 0 ? m.spans[skip - 1].end : m.start;
                Knot before = skip > 1 ? m.spans[skip - 2].end : m.start;
                std::uint32_t ticks = skip > 0 ? m.spans[skip - 1].ticks : 0;
                bool stopped_inside = false;
                for (std::size_t i = skip; i < m.spans.size(); ++i) {
                    const MotionSpan& s = m.spans[i];
                    if (s.end.lambda > commit) {
                        stopped_inside = true;
                        break;
                    }
                    if (!jerk_) {
                        emitter().motion(from, s, run);
                    } else if (!jerk_->raw_span(from, s, pg, piece, run_offset, emitter())) {
                        jerk_failure_ = jerk_->failure();
                        return;
                    }
                    before = from;
                    from = s.end;
                    ticks = s.ticks;
                }
                carry_.q = from.q;
                if (stopped_inside) {
                    cut_ = true;
                    if (ticks ==
                        0) {  // nothing of this piece sent: it starts the next window at rest
                        set_carry(pg, run, run_offset, piece.first, first, false, Knot{}, Knot{},
                                  0);
                    } else {
                        set_carry(pg, run, run_offset, node_at(pg, piece, from.lambda), from.lambda,
                                  true, before, from, ticks);
                    }
                    break;
                }
                carry_.moving = false;
                if (jerk_ && !jerk_->piece_end(from.q, pg, piece, run_offset, emitter())) {
                    jerk_failure_ = jerk_->failure();
                    return;
                }
            }
        }
        if (!cut_ && !exhausted_) {
            // Everything read was planned before the commit point (the last piece ended
            // before it): the next window starts after the last segment, at rest.
            carry_past_end();
            cut_ = true;
        }
    }

    /// Arc length in this grid where the carry's segment starts.
    double segment_start(const PathGrid& pg) const {
        const std::size_t k = carry_node(pg);
        return k < pg.grid.size() ? pg.grid.lambda[k]
                                  : (pg.grid.size() > 0 ? pg.grid.lambda.back() : 0.0);
    }

    /// The next window continues at node `node` of this grid (moving: from knot `last`, which
    /// the span of `ticks` ticks reached from `prev`; else a piece starts there at rest).
    /// `run_offset`: mm of `run` before this grid.
    void set_carry(const PathGrid& pg, const Run& run, double run_offset, std::size_t node,
                   double lambda, bool moving, const Knot& prev, const Knot& last,
                   std::uint32_t ticks) {
        const Grid& g = pg.grid;
        std::size_t seg_first = node;
        while (seg_first > 0 && g.seg[seg_first - 1] == g.seg[node]) --seg_first;
        const double run_start = g.lambda[pg.pieces[run.pieces.front()].first];
        carry_.segment = base_ + g.seg[node];
        carry_.lambda_in_segment = lambda - g.lambda[seg_first];
        carry_.moving = moving;
        carry_.prev = prev;
        carry_.last = last;
        carry_.ticks = ticks;
        carry_.run_offset = run_offset + (g.lambda[seg_first] - run_start);
    }

    /// The next window starts after everything read, at rest.
    void carry_past_end() {
        carry_.segment = base_ + buffer_.size();
        carry_.lambda_in_segment = 0;
        carry_.moving = false;
        carry_.run_offset = 0;
    }

    /// The grid node holding arc length `lambda` inside `piece` (the last node at or before it).
    static std::size_t node_at(const PathGrid& pg, const Piece& piece, double lambda) {
        const auto b = pg.grid.lambda.begin();
        std::size_t k = static_cast<std::size_t>(
            std::upper_bound(b + static_cast<std::ptrdiff_t>(piece.first),
                             b + static_cast<std::ptrdiff_t>(piece.last) + 1, lambda) -
            b);
        k = k == 0 ? 0 : k - 1;
        return std::clamp(k, piece.first, piece.last);
    }

    /// The window's events (with the feeds read for them) to the per-tick check, after the
    /// window before, once its check passed, to the sink. False when a check found a tick over
    /// a limit (nothing of that window goes to the sink then).
    bool deliver() {
        if (!collect_checked()) return false;
        emitter().take(next_.events);
        const auto window_spans = static_cast<std::size_t>(
            std::count_if(next_.events.begin(), next_.events.end(),
                          [](const PlanEvent& e) { return e.kind == PlanEvent::Kind::kSpan; }));
        st_.max_window_spans = std::max(st_.max_window_spans, window_spans);
        check_.submit(next_);
        next_.feeds.clear();
        return true;
    }

    /// Waits for the window in the check and sends its events to the sink; false when its
    /// check failed; true when it passed or none was in the check.
    bool collect_checked() {
        if (!check_.busy()) return true;
        if (!check_.collect(checked_)) return false;
        for (const PlanEvent& e : checked_.events) {
            switch (e.kind) {
                case PlanEvent::Kind::kSpan:
                    sink_.span(e.span);
                    ++spans_;
                    break;
                case PlanEvent::Kind::kPen:
                    sink_.pen(e.pen);
                    ++pens_;
                    break;
                case PlanEvent::Kind::kPause:
                    sink_.pause(e.pause);
                    ++pauses_;
                    break;
            }
        }
        emitter().recycle(checked_.events);
        return true;
    }

    /// The check's job (on its thread): the batch's feeds, then its events tick by tick; true
    /// when every tick so far is within the limits.
    bool check_batch(const CheckBatch& batch) {
        for (const FeedNote& f : batch.feeds) checker_->note_feed(f.subpath, f.pen_down, f.feed);
        for (const PlanEvent& e : batch.events) {
            if (e.kind == PlanEvent::Kind::kSpan) {
                checker_->span(e.span);
                jerk_meter_.span(e.span);
            } else if (e.kind == PlanEvent::Kind::kPen)
                checker_->pen(e.pen);
        }
        return !checker_->over_limits();
    }

    CheckBatch next_;     ///< the feeds read and then the events of the window being planned
    CheckBatch checked_;  ///< the window last collected from the check (storage reused)
    SegmentSource& source_;
    const MachineProfile& profile_;
    const PlanOptions& options_;
    const Limits& limits_;
    PlanSink& sink_;
    PlanStats& st_;
    Progress& report_;
    double lo_, hi_;
    std::unique_ptr<TickChecker> checker_;
    JerkMeter jerk_meter_;  ///< the jerk figures of the PlanCheck (plan_stream's `check`)
    std::optional<SpanEmitter> emitter_;
    JerkSetup jerk_setup_;
    std::optional<JerkStage> jerk_;
    JerkFailure jerk_failure_;
    std::vector<BezierSegment> buffer_;  ///< segments base_ .. base_ + size - 1
    std::vector<double> nominal_;        ///< their nominal_ticks, so each is measured once
    std::size_t base_ = 0;
    bool exhausted_ = false;
    bool cut_ = false;
    Carry carry_;
    double a_min_ = 0, v_axes_ = 0, top_speed_ = 0;
    std::size_t total_ = 0;
    std::size_t spans_ = 0, pens_ = 0, pauses_ = 0;
    double pen_down_length_ = 0, travel_length_ = 0;
    std::size_t last_subpath_ = 0;
    /// Last: destroyed (joined) before the checker and batches its job uses.
    HandoffWorker<CheckBatch> check_;
};

}  // namespace

PlanTotals plan_stream(SegmentSource& source, const MachineProfile& machine_profile,
                       const PlanOptions& requested, PlanSink& sink, PlanStats* stats,
                       const std::function<void(double fraction)>& progress) {
    return plan_stream(source, machine_profile, requested, sink, nullptr, stats, progress);
}

PlanTotals plan_stream(SegmentSource& source, const MachineProfile& machine_profile,
                       const PlanOptions& requested, PlanSink& sink, StreamCheck* stream_check,
                       PlanStats* stats, const std::function<void(double fraction)>& progress) {
    const PlanOptions options = profile_options(requested, machine_profile);
    validate_plan_inputs(machine_profile, options);
    MachineProfile profile = machine_profile;  // what is planned with: spans of regular_span_ticks
    profile.ticks_per_span = jerk_span_ticks(machine_profile, regular_span_ticks(machine_profile));
    Progress report(progress);
    PlanStats local;
    PlanStats& st = stats != nullptr ? *stats : local;
    st = PlanStats{};
    st.segments = source.size_hint();
    st.ticks_per_span = profile.ticks_per_span;
    report(0);
    Limits limits;
    for (const auto& a : profile.axes) {
        limits.velocity.push_back(a.max_velocity);
        limits.acceleration.push_back(a.max_acceleration);
        limits.jerk.push_back(a.max_jerk);
    }
    // The jerk stage's spline through knots rounded to the LSB moves the accelerations by a
    // few hundredths of an LSB/tick^2, and overshoots a little where the filter is as short as
    // a span: the second-order stage leaves it 3 % to 10 %.
    if (limits.has_jerk()) {
        const JerkSetup js = jerk_setup(profile, limits);
        const double headroom =
            0.97 - 0.07 * std::min(1.0, double(profile.ticks_per_span) / js.filter_ticks);
        for (double& a : limits.acceleration) a *= headroom;
    }
    double lo = 0.0, hi = 0.95;
    CornerBlender blended(source, options.corner_blend * profile.chord_tolerance,
                          options.corner_stop_angle);
    SegmentSource& input = options.corner_blend > 0 ? static_cast<SegmentSource&>(blended) : source;
    for (int attempt = 0;; ++attempt) {
        PlanCheck check;
        PlanTotals totals;
        SegmentSource* const check_path = stream_check != nullptr ? stream_check->path : nullptr;
        if (check_path != nullptr && attempt > 0 && !check_path->rewind())
            throw PlanError("the plan needs lowered limits but the checked path cannot rewind");
        WindowPlanner planner(input, profile, options, limits, sink, st, report, lo, hi,
                              check_path);
        if (planner.run(check, totals)) {
            if (stream_check != nullptr) stream_check->result = check;
            st.jerk_filter_ticks = planner.jerk_filter_ticks();
            st.jerk_added_ticks = planner.jerk_added_ticks();
            report(1);
            return totals;
        }
        const JerkFailure jerk = planner.jerk_failure();
        if (jerk.failed && attempt >= options.max_replans) {
            static const char* const rules[] = {"the acceleration step at a join",
                                                "the jerk inside a span", "the end at rest",
                                                "the acceleration limit", "the velocity limit"};
            throw PlanError(
                "cannot meet the jerk limit of axis " + profile.axes[jerk.axis].name + " at " +
                jerk.where + " after " + std::to_string(attempt) +
                " replans with lowered limits (no integer tangents keep every span and join "
                "within it and the velocity and acceleration limits; most often refused: " +
                rules[std::clamp(jerk.rule, 0, 4)] + ")");
        }
        if (attempt >= options.max_replans) {
            std::ostringstream m;
            m << "cannot meet the machine's limits on every tick after " << attempt
              << " replans (velocity at " << 100 * check.max_velocity_fraction
              << " %, acceleration at " << 100 * check.max_acceleration_fraction
              << " % of the limit after the rounding allowance; the exact cubic at "
              << 100 * std::max(check.max_velocity_fraction_exact, check.max_span_velocity_fraction)
              << " % and "
              << 100 * std::max(check.max_acceleration_fraction_exact,
                                check.max_span_acceleration_fraction)
              << " %)";
            throw PlanError(m.str());
        }
        if (!input.rewind() || (planner.sent() && !sink.restart())) {
            throw PlanError(
                "the plan needs lowered limits (a tick over a limit after rounding) but the spans "
                "already sent cannot be taken back");
        }
        if (jerk.failed && jerk.velocity) {
            // The spline through the knots overshoots a velocity limit the second-order stage
            // reached: that axis's velocity a little lower.
            limits.velocity[jerk.axis] *= 0.97;
            st.velocity_scale =
                std::min(st.velocity_scale,
                         limits.velocity[jerk.axis] / profile.axes[jerk.axis].max_velocity);
        }
        for (std::size_t i = 0; i < profile.axes.size() && jerk.failed && !jerk.velocity; ++i) {
            // The jerk stage failed: less acceleration, with the same filter (the filter's jerk
            // and the curvature terms 3 kappa s s'' both fall with it; docs/planner.md §12).
            limits.acceleration[i] *= 0.85;
            st.acceleration_scale = std::min(
                st.acceleration_scale, limits.acceleration[i] / profile.axes[i].max_acceleration);
        }
        for (std::size_t i = 0; i < profile.axes.size() && !jerk.failed; ++i) {
            const double fv =
                std::max(check.axis_velocity_fraction[i], check.axis_velocity_fraction_exact[i]);
            const double fa = std::max(check.axis_acceleration_fraction[i],
                                       check.axis_acceleration_fraction_exact[i]);
            if (fv > 1) limits.velocity[i] *= 0.99 / fv;
            if (fa > 1) limits.acceleration[i] *= 0.99 / fa;
            st.velocity_scale =
                std::min(st.velocity_scale, limits.velocity[i] / profile.axes[i].max_velocity);
            st.acceleration_scale = std::min(
                st.acceleration_scale, limits.acceleration[i] / profile.axes[i].max_acceleration);
        }
        ++st.replans;
        lo = hi;
        hi = lo + (0.99 - lo) * 0.8;
    }
}

}  // namespace pathstream::host
