// Internals of the planner shared by its source files (not installed, not an API).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/planner.hpp"

namespace pathstream::host::planner_detail {

inline constexpr std::size_t kAxesMax = 8;
using Vec = std::array<double, kAxesMax>;  // the first `axes` entries are used, the rest stay 0

/// Summed as a tree: a chain of eight dependent additions costs four times as long, and with
/// two or three axes in use (the rest 0) the result is the chain's, bit for bit.
inline double dot(const Vec& a, const Vec& b) {
    static_assert(kAxesMax == 8);
    const double s01 = a[0] * b[0] + a[1] * b[1], s23 = a[2] * b[2] + a[3] * b[3];
    const double s45 = a[4] * b[4] + a[5] * b[5], s67 = a[6] * b[6] + a[7] * b[7];
    return (s01 + s23) + (s45 + s67);
}
inline double norm(const Vec& a) { return std::sqrt(dot(a, a)); }
inline Vec sub(const Vec& a, const Vec& b) {
    Vec r{};
    for (std::size_t i = 0; i < kAxesMax; ++i) r[i] = a[i] - b[i];
    return r;
}
inline Vec scaled(const Vec& a, double s) {
    Vec r{};
    for (std::size_t i = 0; i < kAxesMax; ++i) r[i] = a[i] * s;
    return r;
}

/// A Bezier segment in flat form.
struct Cubic {
    std::array<Vec, 4> p{};
    /// Axes in use: the evaluations skip the rest (zero), which the hot loops notice.
    std::size_t axes = kAxesMax;

    Vec point(double u) const {
        const double v = 1 - u;
        Vec r{};
        for (std::size_t i = 0; i < axes; ++i) {
            const double a = v * p[0][i] + u * p[1][i], b = v * p[1][i] + u * p[2][i],
                         c = v * p[2][i] + u * p[3][i];
            r[i] = v * (v * a + u * b) + u * (v * b + u * c);
        }
        return r;
    }
    Vec d1(double u) const {
        const double v = 1 - u;
        Vec r{};
        for (std::size_t i = 0; i < axes; ++i) {
            r[i] = 3 * (v * v * (p[1][i] - p[0][i]) + 2 * u * v * (p[2][i] - p[1][i]) + u * u * (p[3][i] - p[2][i]));
        }
        return r;
    }
    Vec d2(double u) const {
        const double v = 1 - u;
        Vec r{};
        for (std::size_t i = 0; i < axes; ++i) {
            r[i] = 6 * (v * (p[2][i] - 2 * p[1][i] + p[0][i]) + u * (p[3][i] - 2 * p[2][i] + p[1][i]));
        }
        return r;
    }
    /// Largest distance of a control point from P0: the segment's size.
    double size() const {
        double s = 0;
        for (std::size_t k = 1; k < 4; ++k) s = std::fmax(s, norm(sub(p[k], p[0])));
        return s;
    }
};

Cubic to_cubic(const BezierSegment& s);

/// |q'(u)|: the speed of `c`'s parameter.
double speed_at(const Cubic& c, double u);

/// Arc length of `c` over [u0, u1] by 5-point Gauss-Legendre quadrature of |q'(u)|.
double arc_length(const Cubic& c, double u0, double u1);

/// Per-axis limits of one planning attempt (mm/s, mm/s^2): the profile's, possibly lowered by
/// a replan.
struct Limits {
    std::vector<double> velocity, acceleration;
    /// mm/s^3 per axis, 0: no jerk limit (docs/planner.md §12). Empty: none on any axis.
    std::vector<double> jerk;
    /// Share of the jerk limit the jerk stage's filter plans with (lowered by replans).
    double jerk_share = 0.75;
    bool has_jerk() const {
        for (const double j : jerk) {
            if (j > 0) return true;
        }
        return false;
    }
};

/// Per-node vectors stored flat, `axes` doubles each (a Vec per node would be 64 bytes).
class VecArray {
public:
    struct ConstRow {
        const double* p;
        std::size_t n;
        double operator[](std::size_t i) const { return i < n ? p[i] : 0.0; }
        operator Vec() const {
            Vec v{};
            for (std::size_t i = 0; i < n; ++i) v[i] = p[i];
            return v;
        }
    };
    struct Row {
        double* p;
        std::size_t n;
        double& operator[](std::size_t i) const { return p[i]; }
        operator Vec() const { return ConstRow{p, n}; }
        const Row& operator=(const Vec& v) const {
            for (std::size_t i = 0; i < n; ++i) p[i] = v[i];
            return *this;
        }
        const Row& operator=(const Row& o) const { return *this = Vec(o); }
    };

    void set_axes(std::size_t axes) { axes_ = axes; }
    void reserve(std::size_t n) { data_.reserve(n * axes_); }
    void push_back(const Vec& v) { data_.insert(data_.end(), v.begin(), v.begin() + static_cast<std::ptrdiff_t>(axes_)); }
    std::size_t size() const { return axes_ == 0 ? 0 : data_.size() / axes_; }
    ConstRow operator[](std::size_t k) const { return {data_.data() + k * axes_, axes_}; }
    Row operator[](std::size_t k) { return {data_.data() + k * axes_, axes_}; }

private:
    std::size_t axes_ = 0;
    std::vector<double> data_;
};

/// The lookahead grid of the whole path: nodes along every non-degenerate segment at
/// increasing arc length `lambda` (mm from the start of the path). Where two segments meet
/// there are two nodes at the same lambda (end of one, start of the next).
struct Grid {
    std::size_t axes = 0;
    std::vector<double> lambda, u;
    std::vector<std::uint32_t> seg;
    VecArray q, tangent, curvature;  ///< point, unit tangent dq/dl, curvature d2q/dl2
    std::vector<double> feed;        ///< requested speed along the path at the node
    VecArray corner_jump;            ///< tangent jump at a crossed corner (0 elsewhere)
    // Per node, derived once the grid is complete (finish_grid), for the forward pass's loops.
    std::vector<double> param_pace;      ///< du/dlambda = 1 / |dq/du| at the node (0 where q' = 0)
    std::vector<double> curvature_norm;  ///< |curvature|
    std::vector<std::uint8_t> corner;    ///< 1 where corner_jump is not 0

    std::size_t size() const { return lambda.size(); }
};

/// A stretch of the path between two stops: nodes first..last of the grid, started and ended
/// at rest. A piece of zero length has first == last.
struct Piece {
    std::size_t first = 0, last = 0;
    std::size_t run = 0;
    double feed = 0;  ///< requested speed along it (mm/s)
};

/// Consecutive segments with the same pen state and subpath: drawn (or travelled) without a
/// pen change. Holds its pieces in order.
struct Run {
    bool pen_down = true;
    std::size_t subpath = 0;
    std::size_t first_segment = 0, last_segment = 0;
    bool pause_before = false;  ///< the first segment's pause and rest (BezierSegment)
    double dwell_before = 0;
    bool dwell_pen_down = false;
    std::vector<std::size_t> pieces;
    Vec start{}, end{};  ///< mm
};

struct PathGrid {
    Grid grid;
    std::vector<Cubic> cubics;
    std::vector<double> cubic_size;  ///< Cubic::size() of each
    std::vector<Piece> pieces;
    std::vector<Run> runs;
    double pen_down_length = 0, travel_length = 0;
};

/// Builds the grid, the stops (sharp corners, cusps, pen changes, ends) and the runs.
/// `profile` gives the feeds. Throws PlanError on unusable input.
/// `first_index`: the global index of segments[0], for messages (a window of a streamed job).
PathGrid build_grid(const std::vector<BezierSegment>& segments, const MachineProfile& profile,
                    const PlanOptions& options, std::size_t first_index = 0);

/// Point and unit tangent at arc length `lambda` inside `piece`. `hint` is a node index to
/// start searching from (updated), for the monotone walk of the forward pass.
struct PathAt {
    Vec q{}, t{};
};
/// `precise` = false skips the arc length's refinement: the point is exactly on the path but
/// its arc length may be off by about 1e-6 of the grid interval (enough for a distance measured
/// across the path; four times cheaper).
PathAt path_at(const PathGrid& g, const Piece& piece, double lambda, std::size_t& hint, bool precise = true);

/// Max x in [0, x_max] such that some y in [y_lo, y_hi] satisfies lo_m <= c_m x + d_m y <= hi_m
/// for every row (each row must contain the origin: lo_m <= 0 <= hi_m, and y_lo <= 0 <= y_hi).
struct LpRow {
    double c, d, lo, hi;
};
double lp_max_x(const LpRow* rows, std::size_t count, double x_max, double y_lo, double y_hi);
/// Max y in [y_lo, y_hi] for a given x; returns false (and y = the least violating value) when
/// no y satisfies the rows.
bool lp_max_y(const LpRow* rows, std::size_t count, double x, double y_lo, double y_hi, double& y);

/// Per-node squared-speed caps: per-axis velocity, feed, chord tolerance, corner rule, with
/// the velocity and feed margins of `options`.
std::vector<double> speed_caps(const PathGrid& g, const Limits& limits, const MachineProfile& profile,
                               const PlanOptions& options);

/// With jerk limits: lowers `caps` (squared speeds) for the curvature's change (kappa' s^3 and
/// curvature steps at joints), for tangent jumps crossed inside spans, and erodes every cap over
/// the distance the jerk stage's box filter of `filter_ticks` averages (docs/planner.md §12).
void jerk_caps(const PathGrid& g, const Limits& limits, const MachineProfile& profile, std::uint32_t filter_ticks,
               std::vector<double>& caps);

/// A span that crosses a corner at speed v turns on axis i at up to 4 v |J_i| / span_time:
/// caps the lookahead's acceleration factor within two spans' travel of every crossed corner
/// to 1 minus that share (at most half), so that the deceleration into it leaves room for it.
/// `caps` are the squared-speed caps (the corner speed is the corner node's cap).
void reserve_for_corners(const PathGrid& g, const Limits& limits, const std::vector<double>& caps,
                         double span_time, std::vector<double>& factor);

/// TOPP-RA backward pass over one piece: beta[k] (k = first..last, indexed by node) is the
/// largest squared speed at node k from which the rest of the piece can still be run to a stop
/// at its end with accelerations limits * accel_factor[k], speed changes costing
/// 1 / tangential_margin times their acceleration. beta[last] = 0.
/// With span_time > 0, dips of the speed caps (dip[k]: squared speed, scratch of the same size)
/// are also approached no faster than spans of that duration can slow down from a knot
/// (x = s^2 falling by at most 1.9 s / span_time per mm), except dips within `end_zone` mm of
/// the piece's end: the motion stops there anyway, and the final span is checked against them.
/// Incremental use: only nodes below `top` are recomputed (beta[top] must be valid), and the
/// pass stops at the first node below `unchanged_below` whose value does not change. Returns
/// the lowest node recomputed.
std::size_t backward_pass(const PathGrid& g, const Piece& piece, const Limits& limits,
                          const std::vector<double>& accel_factor, double tangential_margin,
                          const std::vector<double>& caps, double span_time, double end_zone,
                          std::vector<double>& dip, std::vector<double>& beta,
                          std::size_t top = static_cast<std::size_t>(-1),
                          std::size_t unchanged_below = 0);

/// TOPP-RA forward pass of one piece on its own grid (continuous time, piecewise constant path
/// acceleration between nodes): the optimum's motion time in seconds.
double topp_piece_time(const PathGrid& g, const Piece& piece, const Limits& limits,
                       const std::vector<double>& accel_factor, const std::vector<double>& beta);

/// A knot of the executed motion: arc length, speed, point and velocity vector (mm, mm/s).
struct Knot {
    double lambda = 0, speed = 0;
    Vec q{}, v{};
};
/// A span of the executed motion: `ticks` ticks ending at `end` (it starts at the previous end).
struct MotionSpan {
    std::uint32_t ticks = 0;
    Knot end;
};
struct PieceMotion {
    Knot start;
    std::vector<MotionSpan> spans;
    bool ok = true;
    double fail_lambda = 0;  ///< where the forward pass got stuck (when !ok)
    double fail_speed = 0;   ///< and how fast it was going there
};

/// The executed motion of one piece in whole ticks: knots every ticks_per_span ticks with
/// constant acceleration along the path in each span, the Hermite span between two knots
/// checked against the limits, the speed kept under beta, and the final span ending at rest
/// exactly at the piece's end.
/// Knots are on the LSB grid and their velocities rounded as the emitter rounds tangents, so
/// that what is checked is exactly what the device runs; `start_q` is where the previous piece
/// ended (on the grid).
/// `resume` (optional): a previous attempt whose knots before `resume_lambda` are kept (its
/// spans are moved into the result and cut there).
/// `short_spans`: allow spans shorter than ticks_per_span where a full one cannot be found
/// (the last resort: their tangents are rounded on a different scale).
PieceMotion forward_pass(const PathGrid& g, const Piece& piece, const Limits& limits,
                         const std::vector<double>& caps, const std::vector<double>& beta,
                         const MachineProfile& profile, const PlanOptions& options, const Vec& start_q,
                         PieceMotion* resume = nullptr, double resume_lambda = 0,
                         bool short_spans = false);

/// The lookahead of one window's grid: speed caps, acceleration factors and the backward
/// pass's beta per node, lowered locally by the retries of plan_piece.
struct WindowLookahead {
    WindowLookahead(const PathGrid& pg, const Limits& limits, const MachineProfile& profile,
                    const PlanOptions& options);
    void set_factor(std::size_t k);

    const PathGrid& pg;
    const Limits& limits;
    const MachineProfile& profile;
    const PlanOptions& options;
    double span_time;
    double end_zone;  ///< half an LSB: dips this close to a piece's end count as it (backward_pass)
    std::vector<double> base_caps, caps, local_factor, local_cap, corner_factor, factor, beta, dip;
};

/// Plans one piece: backward pass, forward pass from rest at start_q (or from the last knot
/// of `carried`, whose spans were sent already and are kept first in the result), and the
/// local retries. Throws PlanError naming the place when no whole-tick motion is found.
/// `run_offset`: mm of the run before this window's grid, for that message.
PieceMotion plan_piece(WindowLookahead& lookahead, const Piece& piece, const Vec& start_q, PieceMotion* carried,
                       double run_offset, PlanStats& stats);

/// "subpath N, X mm along it" for a place in a piece.
std::string where(const PathGrid& pg, const Piece& piece, double lambda, double run_offset);

/// Gives `inner`'s segments with every vertex between two straight segments of one run that
/// turn by more than 1e-6 and at most `stop_angle` rad replaced by a blend: the segments are
/// shortened by d each side and a quadratic Bezier (as a cubic) from V - d t1 over V to
/// V + d t2 joins them, tangent to both, passing `deviation` mm from the vertex (d =
/// 2 deviation / sin(turn / 2), at most half of each segment). Joints stay shared exactly.
class CornerBlender : public SegmentSource {
public:
    CornerBlender(SegmentSource& inner, double deviation, double stop_angle);
    bool next(BezierSegment& out) override;
    bool rewind() override;
    std::size_t size_hint() const override { return inner_.size_hint(); }

private:
    void blend(BezierSegment& b);

    SegmentSource& inner_;
    double deviation_, stop_angle_;
    std::deque<BezierSegment> ready_;
    std::optional<BezierSegment> held_;  ///< its end may still be shortened
    double held_original_length_ = -1;
};

/// `options` with what the machine profile sets itself (its corner_stop_angle, when given).
PlanOptions profile_options(const PlanOptions& options, const MachineProfile& profile);
/// The profile and options plan_path accepts (PlanError otherwise).
void validate_plan_inputs(const MachineProfile& profile, const PlanOptions& options);
/// Ticks of a regular span for `profile` (docs/planner.md §5, span length).
std::uint32_t regular_span_ticks(const MachineProfile& profile);

/// LSB of tangent per mm/s of velocity on a span of `ticks` ticks: the one formula the forward
/// pass and the emitter both round tangents with. (Two formulas an ulp apart broke a tie of
/// 1.5 LSB differently: the device got an exact cubic 1.6 % over a limit the forward pass had
/// checked within it.)
inline double tangent_scale(std::uint32_t ticks, double tick_hz, double lsb) {
    return ticks / tick_hz / lsb;
}

/// A velocity (mm/s, one axis) as the tangent of a span in whole LSB, `scale` being the span's
/// tangent_scale: the one rounding (half away from zero) the forward pass and the emitter share.
inline long long scaled_tangent_lsb(double velocity, double scale) {
    const double x = velocity * scale;
    // std::llround inline (it is a library call, and this runs for every axis of every span
    // tried): below 2^52 the fraction x - trunc(x) is exact, so half away from zero is exact.
    if (!(std::fabs(x) < 0x1p52)) return std::llround(x);
    long long i = static_cast<long long>(x);
    const double fraction = x - static_cast<double>(i);
    if (fraction >= 0.5)
        ++i;
    else if (fraction <= -0.5)
        --i;
    return i;
}

/// A point on the LSB grid (mm), rounded as the emitter rounds span end points.
inline Vec on_lsb_grid(const Vec& q, double lsb, std::size_t axes) {
    Vec r{};
    for (std::size_t i = 0; i < axes; ++i) r[i] = static_cast<double>(std::llround(q[i] / lsb)) * lsb;
    return r;
}

/// Distance from points to a set of Bezier segments (the pen-down path), for the plan check.
/// Queries are expected to move along the path: each one first searches the segments around
/// the previous answer (both ways, a window that grows with the step; closed runs wrap), then,
/// only if that finds nothing within `global_below` mm, every segment (pruned by control-point
/// boxes), so that a distance above `global_below` is always the true one. Each candidate
/// segment: branch and bound over de Casteljau halves (a half is dropped when the box of its
/// control points is farther than the best distance so far), pieces flat to 1 um projected on
/// their chord and refined by Newton on (q(u) - p) . q'(u) = 0: the global nearest point, exact
/// to rounding.
class PathProjector {
public:
    PathProjector(std::vector<Cubic> segments, std::vector<std::size_t> index, double global_below);
    /// Distance (mm) from p to the nearest segment; `segment` gets its index (as given).
    double distance(const Vec& p, std::size_t& segment);
    bool empty() const { return segs_.empty(); }

private:
    /// Distance from p to segment i when it is below `bound` (mm), else a value >= bound;
    /// `at` (optional) gets the parameter of the nearest point when one below bound is found.
    double segment_distance(std::size_t i, const Vec& p, double bound, double* at = nullptr) const;
    double box_distance(std::size_t i, const Vec& p) const;
    /// Builds the bounding-box tree over segments order_[first, last) and returns its node.
    std::size_t build_tree(std::size_t first, std::size_t last);
    /// Every segment whose box is nearer than `best` goes to `consider` (which lowers best):
    /// the tree's boxes are pruned against the best distance so far, O(log n) for a point near
    /// the path instead of a scan of every segment.
    template <typename Consider>
    void search_tree(const Vec& p, double& best, Consider&& consider) const;

    /// A node of the bounding-box tree: a leaf holds order_[first, last), an inner node its
    /// two children.
    struct TreeNode {
        Vec lo{}, hi{};
        std::size_t first = 0, last = 0;
        std::size_t left = 0, right = 0;  ///< children (both 0 for a leaf)
    };
    std::vector<TreeNode> tree_;
    std::vector<std::size_t> order_;

    std::vector<Cubic> segs_;
    std::vector<std::size_t> index_;
    std::vector<double> length_;
    std::vector<Vec> lo_, hi_;
    std::vector<std::size_t> run_first_, run_last_;
    double global_below_;
    std::size_t cursor_ = 0;
    Vec last_p_{};
    double last_d_ = 0;
    double last_u_ = 0;  ///< parameter of the last answer on segment cursor_
    bool started_ = false;
};

class FeedTable;
class CoreStepper;

/// The per-tick check of check_plan, fed a plan in order (pen events before the spans at
/// their ticks), so that a streamed plan is checked as it is made.
class TickChecker {
public:
    /// `segments` (optional) give the feeds and, with `deviation`, the path to measure from.
    TickChecker(const MachineProfile& profile, const std::vector<BezierSegment>* segments, bool deviation);
    ~TickChecker();
    TickChecker(const TickChecker&) = delete;
    TickChecker& operator=(const TickChecker&) = delete;
    /// A segment's requested feed (streamed plans give their segments' feeds as they are
    /// read): the first one of a subpath and pen state counts, as in the constructor.
    void note_feed(std::size_t subpath, bool pen_down, double feed);
    void pen(const PenEvent& event);
    /// Runs the span through the core tick by tick; throws PlanError if the core refuses it.
    void span(const CoreSpan& span);
    /// True when a tick or span so far is over a limit (exactly or after the allowance).
    bool over_limits();
    /// The held end point and the rest after it; the figures of the whole plan.
    PlanCheck finish();
    /// Called with every executed tick: its number, the core's setpoint (LSB per axis) and
    /// the pen output of the span playing it (the held end point last).
    using TickObserver = std::function<void(std::uint64_t tick, const std::int64_t* setpoint, bool pen_down)>;
    void observe(TickObserver observer) { observer_ = std::move(observer); }

private:
    bool pen_down_at(std::uint64_t tick);
    bool in_window(std::uint64_t tick);
    /// Tick k's setpoint p and exact value e, from a span with pen output `pen_output` and
    /// requested feed `feed`.
    void visit(const std::array<std::int64_t, kAxesMax>& p, const std::array<double, kAxesMax>& e,
               bool pen_output, double feed);
    void velocity(std::size_t a, double d, double de);
    void acceleration(std::size_t a, std::int64_t second, double de);
    /// The peaks below as fractions of the limits, into out_. A tick's figures are kept in LSB
    /// and divided once here: dividing by a positive limit keeps the order, so the largest
    /// quotient is the quotient of the largest, bit for bit.
    void fold_peaks();

    struct AxisPeaks {
        double velocity_allowed = 0, velocity_raw = 0, velocity_exact = 0;
        double acceleration_allowed = 0, acceleration_raw = 0, acceleration_exact = 0;
    };
    std::array<AxisPeaks, kAxesMax> peaks_{};

    const MachineProfile& profile_;
    std::size_t axes_;
    std::unique_ptr<FeedTable> feeds_;
    bool do_deviation_;
    PlanCheck out_;
    std::array<double, kAxesMax> vlim_{}, alim_{};
    std::unique_ptr<PathProjector> projector_;
    std::unique_ptr<CoreStepper> stepper_;
    std::vector<std::pair<std::uint64_t, std::uint64_t>> windows_;
    std::vector<PenEvent> pens_;
    std::size_t window_index_ = 0, pen_index_ = 0, spans_ = 0;
    bool pen_down_ = false;
    std::uint64_t tick_ = 0;
    std::array<std::int64_t, kAxesMax> p1_{}, p2_{};
    std::array<double, kAxesMax> e1_{}, e2_{};
    double prev_feed_ = 0;
    bool have_prev_span_ = false;
    double distance_ = 0;
    bool have_distance_ = false;
    std::array<double, kAxesMax> last_end_{};  ///< the last span's exact end point (LSB)
    bool last_pen_down_ = false;
    double last_feed_ = 0;
    TickObserver observer_;
};

/// check_plan, with the deviation part optional (the planner's own verification skips it).
PlanCheck check_plan_impl(const Plan& plan, const std::vector<BezierSegment>& segments,
                          const MachineProfile& profile, bool deviation);

/// One event of a plan in the making, in plan order.
struct PlanEvent {
    enum class Kind { kSpan, kPen, kPause };
    Kind kind = Kind::kSpan;
    CoreSpan span;
    PenEvent pen;
    PlanPause pause;
};

/// Turns knots, runs and pen changes into the plan's core spans, pen events, dwells and
/// pauses, in order (docs/planner.md §6). The last span is held back until the next event,
/// because a pause marks the span it follows; finish() lets it go. Throws PlanError when a
/// value is outside the core's range or the core refuses a span.
class SpanEmitter {
public:
    SpanEmitter(const MachineProfile& profile, std::size_t axes, const Vec& start_mm);
    /// The start of a run: its pause, pen change and rests, unless it continues the current
    /// run (the same pen state and subpath: a run cut between two windows).
    void begin_run(const Run& run);
    /// A piece starts at `start_mm`: it must be where the last one ended (within 1 LSB).
    void piece_start(const Vec& start_mm, std::size_t subpath);
    /// The motion span from knot `from` to `span.end`.
    void motion(const Knot& from, const MotionSpan& span, const Run& run);
    using LsbVec = std::array<std::int64_t, kAxesMax>;
    /// A motion span given in LSB: from the current position to `p1` with tangents t0, t1.
    void motion_lsb(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks, std::size_t subpath,
                    bool pen_down);
    /// Where the last span ended (LSB).
    const LsbVec& position() const { return pos_; }
    /// The last span's end acceleration per axis: numerator (LSB/u^2) over `last_ticks()`^2
    /// (0 at rest: before the first span, after a dwell).
    const LsbVec& last_end_acceleration() const { return a_end_; }
    std::uint32_t last_ticks() const { return last_ticks_; }
    /// With jerk limits (LSB/tick^3 per axis; infinity: none) every span is verified against
    /// them exactly: its own jerk and the acceleration step at its join with the last span.
    void set_jerk_limits(const std::array<double, kAxesMax>& jerk_lsb) {
        jerk_lsb_ = jerk_lsb;
        check_jerk_ = true;
    }
    /// The end of the job: the final lift and its dwell, and the held-back span.
    void finish(std::size_t last_subpath);
    /// The events made since the last call, moved into `out` (emptied first through recycle).
    void take(std::vector<PlanEvent>& out);
    /// Empties `used` (events already handed on), keeping its spans' storage for the next
    /// spans: a caller that gives every event back allocates nothing per span once warm.
    void recycle(std::vector<PlanEvent>& used);

    std::uint64_t total_ticks() const { return total_ticks_; }
    std::size_t motion_spans() const { return motion_spans_; }
    std::uint64_t motion_ticks() const { return motion_ticks_; }
    std::uint64_t dwell_ticks() const { return dwell_ticks_; }

private:
    LsbVec quantise(const Vec& mm) const;
    LsbVec tangent(const Vec& velocity, std::uint32_t ticks) const;
    void span(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks, std::size_t subpath,
              bool pen_down);
    void dwell(std::uint64_t ticks, std::size_t subpath, bool pen_down);
    void pen(bool down, std::size_t subpath, bool last);
    void before_pen_down(const Run& run);
    void release();
    void verify_jerk(const LsbVec& p1, const LsbVec& t0, const LsbVec& t1, std::uint32_t ticks, std::size_t subpath);
    [[noreturn]] static void fail(std::size_t subpath, const std::string& what);

    LsbVec a_end_{};
    std::uint32_t last_ticks_ = 1;
    std::array<double, kAxesMax> jerk_lsb_{};
    bool check_jerk_ = false;

    const MachineProfile& profile_;
    std::size_t axes_;
    std::vector<PlanEvent> events_;
    std::vector<CoreSpan> spare_;  ///< spans taken back by take(), their vectors' storage reused
    bool held_ = false;  ///< events_.back() is a span held back
    bool any_span_ = false, last_pen_down_ = false;
    LsbVec pos_{};
    bool pen_ = false;
    bool in_run_ = false;
    std::size_t run_subpath_ = 0;
    bool run_pen_down_ = false;
    std::uint64_t total_ticks_ = 0;
    std::size_t motion_spans_ = 0;
    std::uint64_t motion_ticks_ = 0, dwell_ticks_ = 0;
};


/// Span length and filter of the jerk stage for a profile (docs/planner.md §12).
struct JerkSetup {
    bool active = false;
    std::uint32_t span_ticks = 0;    ///< ticks of every emitted motion span
    std::uint32_t filter_ticks = 0;  ///< M: the box filter's length
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
    bool raw_span(const Knot& from, const MotionSpan& span, const PathGrid& pg, const Piece& piece, double run_offset,
                  SpanEmitter& emitter);
    /// The piece's motion ended at rest (raw end point on the LSB grid: `end_q`); emits the rest.
    bool piece_end(const Vec& end_q, const PathGrid& pg, const Piece& piece, double run_offset, SpanEmitter& emitter);
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
        return std::clamp<std::int64_t>((static_cast<std::int64_t>(i + 1) * n + 2) / 4, std::min<std::int64_t>(1, n - 1), n - 1);
    }
    void check_deviation(std::size_t k, const PathGrid& pg, const Piece& piece, double run_offset) const;
    double filtered(std::int64_t t) const;
    double raw_lambda(double t) const;
    /// Positions of the knots up to raw time `until` (or all, once the piece ended).
    void add_knots(const PathGrid& pg, const Piece& piece);
    void add_targets();
    /// Chooses the tangents of knots chosen_from.. (backtracking), emits the final spans.
    bool choose_and_emit(bool end, const PathGrid& pg, const Piece& piece, double run_offset, SpanEmitter& emitter);
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
