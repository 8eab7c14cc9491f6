// The ring-down fit: a damped oscillation's natural frequency and damping ratio from samples,
// synthetic and from the simulated resonant axis, and the CSV it reads recordings from.
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "pathstream/host/ring_down.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/sim/resonant_axis.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

/// x(t) = rest + A exp(-zeta w t) cos(w_d t + phase), sampled at `hz` for `seconds`.
RingDownSamples damped(double f, double zeta, double hz, double seconds, double rest = 0) {
    const double w = 2 * std::numbers::pi * f, wd = w * std::sqrt(1 - zeta * zeta);
    RingDownSamples s;
    for (double t = 0; t < seconds; t += 1 / hz) {
        s.time.push_back(t);
        s.value.push_back(rest + 0.05 * std::exp(-zeta * w * t) * std::cos(wd * t + 0.3));
    }
    return s;
}

std::string write_file(const std::string& name, const std::string& text) {
    const auto file = std::filesystem::temp_directory_path() / name;
    std::ofstream(file) << text;
    return file.string();
}

std::string error_of(const std::string& text) {
    try {
        load_ring_down_csv(write_file("pathstream_ring_down_test.csv", text));
    } catch (const InputError& e) {
        const std::string what = e.what();
        return what.substr(what.find(".csv:") + 5);
    }
    return "no error";
}

}  // namespace

TEST_CASE("ring-down: a damped sine's frequency and damping", "[calibrate]") {
    for (double f : {12.0, 40.0, 95.0}) {
        for (double zeta : {0.01, 0.05, 0.15}) {
            CAPTURE(f, zeta);
            const RingDown r = fit_ring_down(damped(f, zeta, 1000, 1.0, 3.0));
            CHECK(r.frequency_hz == Approx(f).epsilon(0.005));
            CHECK(r.damping == Approx(zeta).epsilon(0.03));
            CHECK(r.half_cycles >= 4);
        }
    }
}

TEST_CASE("ring-down: the simulated resonant axis's mode comes back", "[calibrate]") {
    // The axis steps 1 mm and rests; its tool rings at the mode through the servo.
    const sim::ResonantMode mode{40, 0.05};
    sim::ResonantAxis axis({200, 1.0}, {mode}, 0.001, 0);
    RingDownSamples s;
    for (int k = 0; k < 1500; ++k) {
        axis.step(1.0);
        if (k >= 40) {  // once the 200 Hz servo has settled
            s.time.push_back(k * 0.001);
            s.value.push_back(axis.tool_position());
        }
    }
    const RingDown r = fit_ring_down(s);
    CHECK(r.frequency_hz == Approx(40).epsilon(0.01));
    CHECK(r.damping == Approx(0.05).epsilon(0.05));
}

TEST_CASE("ring-down: no ringing to measure is an error with the reason", "[calibrate]") {
    RingDownSamples flat;
    for (int k = 0; k < 100; ++k) {
        flat.time.push_back(k * 0.001);
        flat.value.push_back(1.0 - std::exp(-k * 0.05));
    }
    CHECK_THROWS_WITH(fit_ring_down(flat), Catch::Contains("at least 4 are needed"));
    RingDownSamples few = damped(40, 0.05, 1000, 0.01);
    CHECK_THROWS_WITH(fit_ring_down(few), "ring-down: at least 16 samples are needed");
}

TEST_CASE("ring-down CSV: columns by name, errors with the place", "[calibrate]") {
    const std::string ok = write_file("pathstream_ring_down_ok.csv",
                                      "# a recording\nacceleration,time\n1.5,0.000\n-1.0,0.001\n");
    const RingDownSamples s = load_ring_down_csv(ok);
    REQUIRE(s.time.size() == 2);
    CHECK(s.time[1] == 0.001);
    CHECK(s.value[0] == 1.5);
    CHECK(error_of("time,velocity\n0,1\n") ==
          "1:6: unknown column \"velocity\" (expected time and one of position, acceleration)");
    CHECK(error_of("time\n0\n") ==
          "1:1: the header needs a time column and a position or acceleration column");
    CHECK(error_of("time,position\n0,1\n0.001,x\n") == "3:7: \"x\" is not a number");
    CHECK(error_of("time,position\n0,1\n0,2\n") ==
          "3:1: time must increase from one sample to the next");
    CHECK(error_of("time,position\n0,1,2\n") == "2:1: 3 columns, the header has 2");
    CHECK(error_of("# nothing\n") == "1:1: no header line (time,position)");
}
