// The job's length before it is planned: the model from lengths and feeds, its correction by
// the part planned, and the progress events that carry it while planning goes on.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/events.hpp"
#include "pathstream/host/job_estimate.hpp"
#include "pathstream/machine/machine.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

MachineProfile two_axes() {
    MachineProfile m;
    m.tick_hz = 1000;
    m.mm_per_lsb = 0.001;
    m.feed = 50;
    m.travel_feed = 100;
    m.axes = {{"x", 200, 2000}, {"y", 200, 2000}};
    return m;
}

BezierSegment line(double x0, double y0, double x1, double y1, bool pen_down) {
    BezierSegment s;
    s.pen_down = pen_down;
    for (int k = 0; k < 4; ++k) s.p[k] = {x0 + (x1 - x0) * k / 3.0, y0 + (y1 - y0) * k / 3.0};
    return s;
}

}  // namespace

TEST_CASE("the model: each segment at its feed, a stop and a start where the motion rests",
          "[host][estimate]") {
    const MachineProfile m = two_axes();
    // 30 mm of travel at 100 mm/s, then 100 mm drawn at 50 mm/s in two segments: two rests
    // (the job's start and the pen change), each v / a.
    const std::vector<BezierSegment> segments = {line(0, 0, 30, 0, false), line(30, 0, 80, 0, true),
                                                 line(80, 0, 130, 0, true)};
    const JobEstimate e(segments, m);
    CHECK(e.model_length_mm() == Approx(130));
    CHECK(e.model_seconds() == Approx(0.3 + 100.0 / 2000 + 2.0 + 50.0 / 2000));
    CHECK(e.total_ticks(0, 0) == 2375);
    // A feed above an axis's speed along the chord is capped by it: 45 degrees, 200 mm/s per
    // axis, 282.8 mm/s along it.
    BezierSegment fast = line(0, 0, 100, 100, true);
    fast.feed = 1000;
    const double v = 200 * std::sqrt(2.0);
    CHECK(JobEstimate({fast}, m).model_seconds() == Approx(100 * std::sqrt(2.0) / v + v / 2000));
}

TEST_CASE("the estimate follows the planner: what it made of the planned part scales the rest",
          "[host][estimate]") {
    const MachineProfile m = two_axes();
    std::vector<BezierSegment> segments;
    for (int k = 0; k < 10; ++k) segments.push_back(line(10.0 * k, 0, 10.0 * (k + 1), 0, true));
    const JobEstimate e(segments, m);
    const double model = e.model_seconds();  // 2 s + one start
    // Half the path planned in exactly the model's time: the estimate is the model.
    const std::uint64_t half = static_cast<std::uint64_t>(std::llround((model - 1.0) * 1000));
    CHECK(e.total_ticks(50, half) == Approx(model * 1000).margin(1));
    // Planned 1.5 times as long as the model said: the rest is too.
    const std::uint64_t slow = half * 3 / 2;
    CHECK(e.total_ticks(50, slow) == Approx(slow + 1.5 * (model * 1000 - half)).margin(2));
    // Everything planned: the planned ticks themselves.
    CHECK(e.total_ticks(100, 4321) == 4321);
}

TEST_CASE("progress events: an estimate while planning, the whole drawing after a resume",
          "[host][estimate][events]") {
    const MachineProfile m = two_axes();
    std::FILE* f = std::tmpfile();
    REQUIRE(f != nullptr);
    EventChannel channel;
    channel.writer = std::make_unique<NdjsonWriter>(f);
    channel.progress_hz = 1000;
    JobEvents events(channel, m, {"stream", "d.svg", "modbus-tcp://x", 1});
    CHECK_FALSE(events.progress(100));  // nothing known, no estimate
    std::uint64_t estimate = 4000;
    events.set_progress_basis(0,
                              [&estimate]() -> std::optional<std::uint64_t> { return estimate; });
    const auto p = events.progress(1000);
    REQUIRE(p);
    CHECK(p->estimated);
    CHECK(p->fraction == Approx(0.25));
    CHECK(p->ticks_left == 3000);
    // An estimate below what already ran never reads as done.
    estimate = 900;
    CHECK(events.progress(1000)->fraction < 1.0);
    // Totals known: exact, and a resume's part before counts.
    events.set_totals(3000, 10, 0);
    events.set_progress_basis(1000, {});
    const auto q = events.progress(1500);
    REQUIRE(q);
    CHECK_FALSE(q->estimated);
    CHECK(q->fraction == Approx(2500.0 / 4000.0));
    CHECK(q->ticks_left == 1500);
    channel.writer.reset();
}

TEST_CASE("the bar's pen is the device's output: up at a pause inside a pen-down job",
          "[host][events]") {
    const MachineProfile m = two_axes();
    EventChannel channel;
    JobEvents events(channel, m, {"stream", "d.svg", "modbus-tcp://x", 1});
    CoreSpan span;
    span.ticks = 100;
    span.pen_down = true;
    events.add_span(span);
    events.add_span(span);
    JobSample s;
    s.state = device::DeviceState::kRunning;  // running
    s.started = true;
    s.next_span = 1;
    s.ticks = 150;
    s.pen_output = true;
    events.sample(s);
    CHECK(events.status_text().find("pen down") != std::string::npos);
    s.state =
        device::DeviceState::kHolding;  // holding at a programmed pause: the device raised the pen
    s.pen_output = false;
    events.sample(s);
    CHECK(events.status_text().find("pen up") != std::string::npos);
    s.pen_output.reset();  // no status of the pen (sim): the span's
    events.sample(s);
    CHECK(events.status_text().find("pen down") != std::string::npos);
}
