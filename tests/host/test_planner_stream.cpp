// plan_stream: the path planned in windows with a bounded lookahead. Windows of any size give
// the plan of one window over the whole path (within the grid's rounding), every span passes
// the per-tick check, and a long generated job plans under a memory ceiling the whole-path
// planner could not meet.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <random>
#include <string>

#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/segment_source.hpp"
#include "pen_plotter_profile.hpp"
#include "random_walk_source.hpp"

using namespace pathstream::host;
using pathstream::host::test::pen_plotter;
using pathstream::host::test::RandomWalkSource;

namespace {

/// Counts what a streamed plan gives and checks it is continuous (each span starts where the
/// last one ended); holds nothing.
class CountingSink : public PlanSink {
public:
    void span(const CoreSpan& s) override {
        ++spans;
        ticks += s.ticks;
        if (have_last) {
            for (std::size_t a = 0; a < s.control.size(); ++a) {
                if (s.control[a][0] != last[a]) ++discontinuities;
            }
        }
        last.resize(s.control.size());
        for (std::size_t a = 0; a < s.control.size(); ++a) last[a] = s.control[a][1];
        have_last = true;
    }
    void pen(const PenEvent&) override { ++pens; }
    void pause(const PlanPause&) override {}
    std::size_t spans = 0, pens = 0, discontinuities = 0;
    std::uint64_t ticks = 0;
    std::vector<std::int32_t> last;
    bool have_last = false;
};

std::vector<BezierSegment> collect(SegmentSource& source) {
    std::vector<BezierSegment> out;
    BezierSegment s;
    while (source.next(s)) out.push_back(s);
    source.rewind();
    return out;
}

/// VmSize of this process in bytes (the address space RLIMIT_AS limits).
[[maybe_unused]] std::size_t address_space() {
    std::ifstream f("/proc/self/status");
    std::string key;
    while (f >> key) {
        if (key == "VmSize:") {
            std::size_t kb = 0;
            f >> kb;
            return kb * 1024;
        }
        std::getline(f, key);
    }
    return 0;
}

}  // namespace

TEST_CASE("windows of any size plan the path a single window plans", "[planner][stream]") {
    RandomWalkSource walk(3000, 5);
    const std::vector<BezierSegment> segments = collect(walk);
    const MachineProfile p = pen_plotter();
    PlanOptions whole;
    whole.window_segments = 1u << 20;
    const Plan reference = plan_path(segments, p, whole);
    for (const std::size_t window : {16u, 100u, 700u}) {
        INFO("window of " << window << " segments");
        PlanOptions o;
        o.window_segments = window;
        const Plan plan = plan_path(segments, p, o);
        const PlanCheck check = check_plan(plan, segments, p);
        CHECK(check.within_limits);
        CHECK(check.max_deviation <= p.chord_tolerance + 1.5 * std::sqrt(2.0) * p.mm_per_lsb);
        CHECK(check.ticks_checked == plan.total_ticks + 1);
        // The horizon is longer than any stopping distance, so the windows see what the whole
        // path's lookahead sees: the same motion up to the retries' local choices.
        CHECK(static_cast<double>(plan.total_ticks) ==
              Approx(static_cast<double>(reference.total_ticks)).epsilon(0.002));
        CHECK(plan.pen.size() == reference.pen.size());
        CHECK(plan.path_length == Approx(reference.path_length).epsilon(1e-9));
    }
}

TEST_CASE("a streamed plan comes out continuous and matches plan_path", "[planner][stream]") {
    RandomWalkSource walk(5000, 9);
    const MachineProfile p = pen_plotter();
    CountingSink sink;
    PlanStats stats;
    const PlanTotals totals = plan_stream(walk, p, PlanOptions{}, sink, &stats);
    CHECK(sink.discontinuities == 0);
    CHECK(sink.spans == totals.spans);
    CHECK(sink.ticks == totals.total_ticks);
    CHECK(sink.pens == 2);  // down at the start, up at the end
    CHECK(stats.motion_spans > 0);
    walk.rewind();
    const Plan plan = plan_path(collect(walk), p);
    CHECK(plan.total_ticks == totals.total_ticks);
    CHECK(plan.spans.size() == totals.spans);
}

TEST_CASE("a long job plans under a memory ceiling the whole-path planner needs many times over",
          "[planner][stream]") {
#ifdef PATHSTREAM_SANITIZED
    SUCCEED("skipped: sanitizers reserve address space beyond any ceiling");
#else
    // 100,000 segments: the whole-path planner held ~2.7 KB per segment (270 MB here); the
    // windows hold a few thousand segments whatever the length. The child process plans under
    // RLIMIT_AS = what it has mapped now + 96 MB, and reports through its exit status.
    const std::size_t ceiling = address_space() + (std::size_t{96} << 20);
    REQUIRE(ceiling > (std::size_t{96} << 20));
    const pid_t child = fork();
    REQUIRE(child >= 0);
    if (child == 0) {
        rlimit limit{ceiling, ceiling};
        if (setrlimit(RLIMIT_AS, &limit) != 0) _exit(3);
        try {
            RandomWalkSource walk(100000, 11);
            CountingSink sink;
            const PlanTotals totals = plan_stream(walk, pen_plotter(), PlanOptions{}, sink);
            _exit(sink.discontinuities == 0 && totals.spans > 200000 && sink.spans == totals.spans
                      ? 0
                      : 1);
        } catch (const std::bad_alloc&) {
            _exit(2);
        } catch (...) {
            _exit(4);
        }
    }
    int status = 0;
    REQUIRE(waitpid(child, &status, 0) == child);
    REQUIRE(WIFEXITED(status));
    INFO(
        "exit status 0: planned; 1: wrong plan; 2: out of memory; 3: setrlimit failed; 4: other "
        "error");
    CHECK(WEXITSTATUS(status) == 0);
#endif
}

TEST_CASE("PlanChecker on a streamed plan gives check_plan's figures and the core's setpoints",
          "[planner][stream]") {
    Path path;
    path.axes = 2;
    for (int c = 0; c < 3; ++c) {
        Subpath s;
        s.basis = PathBasis::kCatmullRom;
        for (int i = 0; i < 30; ++i)
            s.points.push_back({20.0 * c + 8 * std::cos(i * 0.7), 8 * std::sin(i * 0.9)});
        path.subpaths.push_back(s);
    }
    const auto segments = to_bezier_segments(path);
    const MachineProfile p = pen_plotter();
    PlanOptions o;
    o.window_segments = 20;
    const Plan plan = plan_path(segments, p, o);
    const PlanCheck whole = check_plan(plan, segments, p);

    std::vector<std::array<std::int64_t, 3>> played;
    play_through_core(plan.spans, 2, [&](const PlayedTick& t) {
        played.push_back({t.setpoint[0], t.setpoint[1], t.pen_down ? 1 : 0});
    });
    VectorSegmentSource source(segments);
    PlanChecker checker(segments, p);
    std::vector<std::array<std::int64_t, 3>> streamed;
    checker.on_tick([&](std::uint64_t tick, const std::int64_t* setpoint, bool pen_down) {
        CHECK(tick == streamed.size());
        streamed.push_back({setpoint[0], setpoint[1], pen_down ? 1 : 0});
    });
    const PlanTotals totals = plan_stream(source, p, o, checker);
    const PlanCheck check = checker.finish();
    CHECK(streamed == played);
    CHECK(checker.spans() == plan.spans.size());
    CHECK(checker.pen_changes() == plan.pen.size());
    CHECK(totals.total_ticks == plan.total_ticks);
    CHECK(check.within_limits == whole.within_limits);
    CHECK(check.max_deviation == whole.max_deviation);
    CHECK(check.worst_deviation_tick == whole.worst_deviation_tick);
    CHECK(check.ticks_checked == whole.ticks_checked);
    CHECK(check.max_acceleration_fraction_exact == whole.max_acceleration_fraction_exact);
    CHECK(check.axis_max_step == whole.axis_max_step);
}

TEST_CASE("PlanChecker reading the path as it goes gives check_plan's figures",
          "[planner][stream]") {
    // Three subpaths (two travels, feeds per subpath) and, in the long one, more segments than
    // the deviation's window holds ahead and behind: the window moves along while the figures
    // stay those of the whole path.
    Path path;
    path.axes = 2;
    for (int c = 0; c < 3; ++c) {
        Subpath s;
        s.basis = c == 1 ? PathBasis::kPolyline : PathBasis::kBSpline;
        s.feed = c == 2 ? 30 : 0;
        const int n = c == 0 ? 12000 : 40;
        for (int i = 0; i < n; ++i) {  // a spiral: no turn comes back near an earlier one
            const double r = 3 + 0.002 * i, a = 0.1 * i;
            s.points.push_back({60.0 * c + r * std::cos(a), r * std::sin(a)});
        }
        path.subpaths.push_back(s);
    }
    const MachineProfile p = pen_plotter();
    const auto segments = to_bezier_segments(path);
    REQUIRE(segments.size() > 2 * (std::size_t{4096} + 1024));  // PathWindow kAhead, kBehind
    PlanChecker whole(segments, p);
    PathSegmentSource planned(path), checked(path);
    PlanChecker streamed(checked, p);
    struct Both : PlanSink {
        PlanChecker& a;
        PlanChecker& b;
        Both(PlanChecker& x, PlanChecker& y) : a(x), b(y) {}
        void span(const CoreSpan& s) override {
            a.span(s);
            b.span(s);
        }
        void pen(const PenEvent& e) override {
            a.pen(e);
            b.pen(e);
        }
        void pause(const PlanPause& q) override {
            a.pause(q);
            b.pause(q);
        }
    } both(whole, streamed);
    (void)plan_stream(planned, p, PlanOptions{}, both);
    const PlanCheck w = whole.finish(), s = streamed.finish();
    CHECK(s.within_limits == w.within_limits);
    INFO(w.ticks_checked);
    CHECK(w.max_deviation > 0);
    CHECK(s.max_deviation == w.max_deviation);
    CHECK(s.worst_deviation_tick == w.worst_deviation_tick);
    CHECK(s.ticks_checked == w.ticks_checked);
    CHECK(s.max_feed_fraction == w.max_feed_fraction);
    CHECK(s.axis_max_step == w.axis_max_step);
    CHECK(s.axis_max_second_difference == w.axis_max_second_difference);
}

TEST_CASE("a slow job's windows hold a bounded number of spans, not the job", "[planner][stream]") {
    // 100 straight 2 mm moves at 10 mm/min (about 1.2 M ticks with the corner stops), far
    // fewer segments than a window reads: its reading stops at about window_ticks of motion
    // (more where the window must reach past the stopping distance at the machine's feed).
    Path path;
    path.axes = 2;
    Subpath s;
    s.basis = PathBasis::kPolyline;
    s.feed = 10.0 / 60;
    for (int i = 0; i <= 100; ++i) s.points.push_back({10 + 1.5 * i, 10 + 1.3 * (i % 2)});
    path.subpaths.push_back(s);
    const MachineProfile p = pen_plotter();
    PathSegmentSource source(path);
    CountingSink sink;
    PlanStats stats;
    const PlanOptions o;
    const PlanTotals totals = plan_stream(source, p, o, sink, &stats);
    CHECK(sink.discontinuities == 0);
    CHECK(totals.total_ticks > 1150000);  // 198 mm at 1/6 mm/s: 1.19 M ticks at least
    INFO("spans " << totals.spans << ", ticks per span " << stats.ticks_per_span);
    CHECK(stats.max_window_spans > 0);
    CHECK(stats.max_window_spans * stats.ticks_per_span < 4 * o.window_ticks);
    CHECK(stats.max_window_spans < totals.spans / 3);
}
