// Residual vibration and contour error: the meters on made-up ticks, then on the simulated
// device with and without a ringing mode.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "pathstream/machine/core_span.hpp"
#include "pathstream/machine/shaper_design.hpp"
#include "pathstream/sim/contour_error.hpp"
#include "pathstream/sim/device.hpp"
#include "pathstream/sim/residual_vibration.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"

using namespace pathstream;
using host::CoreSpan;
using host::MachineProfile;
using sim::ContourErrorMeter;
using sim::ResidualVibrationMeter;
using sim::SimOptions;
using sim::SimulationResult;

namespace {

/// A Hermite span from rest to rest (zero tangents: a smooth point-to-point move), or a dwell
/// when from == to.
CoreSpan move(const std::vector<std::int32_t>& from, const std::vector<std::int32_t>& to,
              std::uint32_t ticks) {
    CoreSpan s;
    s.basis = Basis::kHermite;
    s.ticks = ticks;
    s.pen_down = true;
    REQUIRE(make_span_timing(Basis::kHermite, ticks, s.timing) == Status::kOk);
    for (std::size_t a = 0; a < from.size(); ++a) {
        s.control.push_back({from[a], to[a], 0, 0});
        const std::int32_t p[4] = {from[a], to[a], 0, 0};
        TickCubic cubic;
        REQUIRE(make_tick_cubic(Basis::kHermite, p, s.timing, cubic) == Status::kOk);
        s.cubic.push_back(cubic);
    }
    return s;
}

/// Along x, stop, along y, stop: two stops of 0.5 s.
std::vector<CoreSpan> two_stops() {
    return {move({0, 0}, {20000, 0}, 400), move({20000, 0}, {20000, 0}, 500),
            move({20000, 0}, {20000, 20000}, 400), move({20000, 20000}, {20000, 20000}, 500)};
}

MachineProfile plotter() {
    MachineProfile m;
    m.axes = {{"x", 200.0, 5000.0}, {"y", 200.0, 5000.0}};
    m.mm_per_lsb = 0.001;
    m.tick_hz = 1000;
    return m;
}

SimulationResult run(sim::PlantModel plant, std::vector<std::vector<sim::ResonantMode>> modes) {
    SimOptions o;
    o.plant = plant;
    o.servo.bandwidth_hz = 200;  // stiff: it settles within 1.5 um of the stop
    o.modes = std::move(modes);
    o.record_ticks = false;
    return sim::simulate(two_stops(), plotter(), o);
}

}  // namespace

TEST_CASE("residual vibration is the largest tool distance from the carriage after each stop",
          "[sim][vibration]") {
    ResidualVibrationMeter meter(1, 20, 5);
    // The carriage is at the command here: the tool rings about its rest position.
    const auto tick = [&](double command, double tool) { meter.add(&command, &tool, &command); };
    tick(0, 0), tick(0, 0.5);  // at rest before any motion: no stop
    for (int k = 1; k <= 5; ++k) tick(k, k - 0.5);
    // Stop 1 at 5: the tool overshoots to 5.4, rings; ticks past the window do not count.
    tick(5, 5.4), tick(5, 4.7), tick(5, 5.2);
    for (int k = 0; k < 17; ++k) tick(5, 5.0);
    tick(5, 9.0);                            // tick 21 of the stop: outside its 20-tick window
    tick(6, 6), tick(6, 6.1), tick(6, 6.1);  // a hold of 2 ticks: slow motion, no stop
    tick(7, 7), tick(7, 7.2);                // the run ends in a stop of one tick: it counts
    const sim::ResidualVibration r = meter.finish();
    CHECK(r.stops == 2);
    CHECK(r.window_ticks == 20);
    CHECK(r.max_mm == Approx(0.4));
    CHECK(r.max_tick == 7);
    CHECK(r.max_tool_mm == std::vector<double>{5.4});
    CHECK(r.max_rest_mm == std::vector<double>{5.0});
    CHECK(r.rms_mm == Approx(std::sqrt((0.4 * 0.4 + 0.2 * 0.2) / 2)));
    CHECK(sim::residual_window_ticks(1000, 40) == 125);
    CHECK(sim::residual_window_ticks(1000, 2) == 1000);
    CHECK(sim::residual_window_ticks(1000, 0) == 1000);
}

TEST_CASE("contour error is the distance to the setpoints' polyline, not the lag along it",
          "[sim][contour]") {
    ContourErrorMeter meter(2, 64);
    // A right-angle corner at (10, 0): along x, then along y, 0.1 mm per tick.
    std::vector<std::array<double, 2>> path;
    for (int k = 0; k <= 100; ++k) path.push_back({0.1 * k, 0});
    for (int k = 1; k <= 100; ++k) path.push_back({10, 0.1 * k});
    for (std::size_t k = 0; k < path.size(); ++k) {
        // The tool lags 20 ticks along the path and sits 0.05 mm off it, on the outside of the
        // corner (y < 0 along x, x > 10 along y); past the corner it cuts it: (9.9, 0.3).
        std::array<double, 2> tool = path[k < 20 ? 0 : k - 20];
        if (tool[1] == 0)
            tool[1] -= 0.05;
        else
            tool[0] += 0.05;
        if (k == 150) tool = {9.9, 0.3};
        meter.add(path[k].data(), tool.data());
    }
    const sim::ContourError c = meter.finish();
    CHECK(c.max_mm == Approx(0.1));  // (9.9, 0.3): 0.1 from the y leg
    CHECK(c.max_tick == 150);
    CHECK(c.max_path_mm[0] == Approx(10.0));
    CHECK(c.max_path_mm[1] == Approx(0.3));
    CHECK(c.rms_mm > 0.05);
    CHECK(c.rms_mm < 0.051);
    CHECK(c.back_ticks == 64);
    CHECK(c.ahead_ticks == sim::kContourAheadTicks);
    // The window around the worst tick: tool ticks 86..200, and the path they follow.
    CHECK(c.window.first_tool_tick == 86);
    CHECK(c.window.tool_mm.size() == 2 * (200 - 86 + 1));
    REQUIRE(c.window.path_mm.size() >= 2);
    CHECK(c.window.path_mm[0] <= 8.6);
    CHECK(c.window.path_mm.back() == Approx(10.0));
    CHECK(sim::contour_back_ticks(1000, 0) == 64);
    CHECK(sim::contour_back_ticks(1000, 2 / (2 * std::numbers::pi * 50)) == 64 + 26);
    CHECK(sim::contour_back_ticks(1000, 100) == 4096);
}

TEST_CASE("the ideal plant has no residual vibration and no contour error", "[sim][vibration]") {
    const SimulationResult r = run(sim::PlantModel::kIdeal, {});
    CHECK(r.residual.stops == 2);
    CHECK(r.residual.max_mm == 0);
    CHECK(r.residual.rms_mm == 0);
    CHECK(r.contour.max_mm == 0);
    CHECK(r.contour.rms_mm == 0);
}

TEST_CASE("a 40 Hz mode with zeta 0.05 rings after every stop", "[sim][vibration]") {
    const SimulationResult servo = run(sim::PlantModel::kServo, {});
    const sim::ResonantMode mode{40, 0.05};
    const SimulationResult rings = run(sim::PlantModel::kServo, {{mode}, {mode}});
    CHECK(servo.residual.stops == 2);
    CHECK(rings.residual.stops == 2);
    CHECK(rings.residual.window_ticks == 125);  // 5 periods of 40 Hz
    // The smooth moves stop with an acceleration step of 6 d / T^2 = 750 mm/s^2: the mode
    // rings with about a / w^2 = 12 um; the servo alone has no mode to ring (it closes its lag
    // of 3 a / w^2 = 1.4 um without overshoot: following error, not vibration).
    CHECK(servo.residual.max_mm == 0);
    CHECK(rings.residual.max_mm > 0.008);
    CHECK(rings.residual.rms_mm > 0);
    CHECK(rings.residual.rms_mm <= rings.residual.max_mm);
    CHECK(rings.contour.max_mm > servo.contour.max_mm);
    CHECK(rings.following[0].max_mm > 0);
    // The last stop rings until the run ends: its peak is within the stop.
    CHECK(rings.residual.max_tick >= 400);
}

TEST_CASE("an input shaper tuned to the mode stops the ringing", "[sim][vibration][shaper]") {
    const sim::ResonantMode mode{40, 0.05};
    const SimulationResult rings = run(sim::PlantModel::kServo, {{mode}, {mode}});
    SimOptions o;
    o.plant = sim::PlantModel::kServo;
    o.servo.bandwidth_hz = 200;
    o.modes = {{mode}, {mode}};
    o.record_ticks = false;
    for (host::ShaperType type : {host::ShaperType::kMzv, host::ShaperType::kEi}) {
        const auto taps = host::design_shaper_taps({type, 40, 0.05}, plotter().tick_hz,
                                                   host::kDeviceShaperHistoryTicks);
        o.shaper = {taps, taps};
        const SimulationResult shaped = sim::simulate(two_stops(), plotter(), o);
        CAPTURE(host::shaper_type_name(type), rings.residual.max_mm, shaped.residual.max_mm);
        CHECK(shaped.residual.stops == 2);
        // A tenfold cut at least on this short path with a stiff servo; bench_shaping holds
        // the families to their goals on the example drawings.
        CHECK(shaped.residual.max_mm * 10 < rings.residual.max_mm);
        // The run lasts the longest delay longer, and ends at the end point.
        CHECK(shaped.ticks == rings.ticks + taps.back().delay);
    }
    o.shaper = {{{0, 1}}};  // weights that do not sum to one
    CHECK_THROWS_WITH(sim::simulate(two_stops(), plotter(), o),
                      "axis 0: the device refuses these input shaper taps");
}

TEST_CASE("resonant modes need the servo plant and one list per axis at most", "[sim]") {
    CHECK_THROWS_WITH(run(sim::PlantModel::kIdeal, {{{40, 0.05}}}),
                      "resonant modes need the servo plant");
    CHECK_THROWS_WITH(run(sim::PlantModel::kServo, {{}, {}, {{40, 0.05}}}),
                      "resonant modes given for 3 axes; the plan has 2");
    CHECK_THROWS_WITH(run(sim::PlantModel::kServo, {{{600, 0.05}}}),
                      Catch::Contains("mode frequency 600 Hz is impossible"));
}

TEST_CASE("contour error equals a brute-force search of the same window", "[sim][contour]") {
    const std::uint64_t back = 20, ahead = 7;
    ContourErrorMeter meter(3, back, ahead);
    std::vector<std::array<double, 3>> reference, tool;
    std::uint32_t seed = 12345;
    const auto random = [&] {
        seed = seed * 1664525u + 1013904223u;
        return static_cast<double>(seed >> 8) / 16777216.0 - 0.5;
    };
    std::array<double, 3> r{0, 0, 0};
    for (int k = 0; k < 3000; ++k) {
        if (k % 50 >= 10) {  // moves with rests between them
            for (double& v : r) v = std::round((v + random()) * 100) / 100;
        }
        reference.push_back(r);
        std::array<double, 3> t = reference[k >= 5 ? k - 5 : 0];
        for (double& v : t) v += 0.3 * random();
        tool.push_back(t);
        meter.add(reference.back().data(), tool.back().data());
    }
    const sim::ContourError c = meter.finish();
    // Brute force: each tool tick against every vertex and segment of the setpoints in effect
    // from tick j - back to tick j + ahead.
    const auto distance = [](const std::array<double, 3>& p, const std::array<double, 3>& a,
                             const std::array<double, 3>& b) {
        double ab_ab = 0, ap_ab = 0;
        for (int x = 0; x < 3; ++x) {
            ab_ab += (b[x] - a[x]) * (b[x] - a[x]);
            ap_ab += (p[x] - a[x]) * (b[x] - a[x]);
        }
        const double t = ab_ab > 0 ? std::clamp(ap_ab / ab_ab, 0.0, 1.0) : 0.0;
        double s = 0;
        for (int x = 0; x < 3; ++x) s += std::pow(p[x] - (a[x] + t * (b[x] - a[x])), 2);
        return std::sqrt(s);
    };
    double max = 0, squares = 0;
    std::size_t max_tick = 0;
    const std::size_t n = reference.size();
    for (std::size_t j = 0; j < n; ++j) {
        const std::size_t from = j > back ? j - back : 0, to = std::min(n - 1, j + ahead);
        double best = 1e300;
        for (std::size_t k = from; k <= to; ++k) {
            best = std::min(best, distance(tool[j], reference[k], reference[k]));
            if (k < to) best = std::min(best, distance(tool[j], reference[k], reference[k + 1]));
        }
        squares += best * best;
        if (best > max) max = best, max_tick = j;
    }
    CHECK(c.max_mm == Approx(max).epsilon(1e-12));
    CHECK(c.max_tick == max_tick);
    CHECK(c.rms_mm == Approx(std::sqrt(squares / static_cast<double>(n))).epsilon(1e-12));
}
