// Shaper design: the families' impulses, their taps on the tick grid, and the vibration they
// leave at and around the tuned frequency.
#include <catch2/catch.hpp>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "pathstream/machine/shaper_design.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

constexpr ShaperType kTypes[] = {ShaperType::kZv, ShaperType::kZvd,       ShaperType::kMzv,
                                 ShaperType::kEi, ShaperType::kTwoHumpEi, ShaperType::kThreeHumpEi};

/// The continuous impulses' residual vibration on a mode (the textbook formula), independent
/// of the taps' arithmetic.
double continuous_residual(const std::vector<ShaperImpulse>& impulses, double f, double zeta) {
    const double w = 2 * std::numbers::pi * f, wd = w * std::sqrt(1 - zeta * zeta);
    const double last = impulses.back().time;
    double c = 0, s = 0;
    for (const ShaperImpulse& i : impulses) {
        const double decay = std::exp(zeta * w * (i.time - last));
        c += i.weight * decay * std::cos(wd * i.time);
        s += i.weight * decay * std::sin(wd * i.time);
    }
    return std::hypot(c, s);
}

}  // namespace

TEST_CASE("shaper families have positive impulses summing to one", "[shaper]") {
    for (ShaperType type : kTypes) {
        CAPTURE(shaper_type_name(type));
        const auto impulses = shaper_impulses({type, 40, 0.1});
        double sum = 0;
        for (const ShaperImpulse& i : impulses) {
            CHECK(i.weight > 0);
            sum += i.weight;
        }
        CHECK(sum == Approx(1).epsilon(1e-12));
        CHECK(impulses.front().time == 0);
        REQUIRE(shaper_type_from_name(shaper_type_name(type)) == type);
    }
    CHECK_FALSE(shaper_type_from_name("bogus"));
}

TEST_CASE("the continuous shapers cancel the tuned mode", "[shaper]") {
    // ZV, ZVD and MZV leave nothing at the design point; the EI family leaves its tolerance.
    for (double zeta : {0.0, 0.05, 0.1}) {
        for (ShaperType type : {ShaperType::kZv, ShaperType::kZvd, ShaperType::kMzv}) {
            CAPTURE(shaper_type_name(type), zeta);
            CHECK(continuous_residual(shaper_impulses({type, 40, zeta}), 40, zeta) < 1e-9);
        }
        CHECK(continuous_residual(shaper_impulses({ShaperType::kEi, 40, zeta}), 40, zeta) < 0.051);
    }
    // The ZV shaper's two impulses half a damped period apart.
    const auto zv = shaper_impulses({ShaperType::kZv, 50, 0});
    REQUIRE(zv.size() == 2);
    CHECK(zv[1].time == Approx(0.01));
    CHECK(zv[1].weight == Approx(0.5));
}

TEST_CASE("shaper taps on the tick grid sum exactly to one and keep the cancellation", "[shaper]") {
    for (double tick_hz : {1000.0, 10000.0}) {
        for (ShaperType type : kTypes) {
            CAPTURE(tick_hz, shaper_type_name(type));
            const auto taps = design_shaper_taps({type, 40, 0.05}, tick_hz, 4096);
            REQUIRE(check_shaper_taps(taps.data(), static_cast<std::uint32_t>(taps.size()), 4096) ==
                    Status::kOk);
            const double tuned = residual_vibration_ratio(taps, tick_hz, 40, 0.05);
            // Splitting impulses between ticks costs little at 1 kHz and less at 10 kHz: every
            // family cuts the tuned mode at least 20x.
            CHECK(tuned < 0.05);
            const double off = residual_vibration_ratio(taps, tick_hz, 48, 0.05);
            if (type == ShaperType::kEi || type == ShaperType::kTwoHumpEi ||
                type == ShaperType::kThreeHumpEi) {
                CHECK(off < 0.2);  // the EI class: at least 5x with the mode 20 % off
            }
            CHECK(residual_vibration_ratio({}, tick_hz, 40, 0.05) == 1);
        }
    }
}

TEST_CASE("shaper design refuses frequencies the device cannot shape", "[shaper]") {
    CHECK_THROWS_WITH(design_shaper_taps({ShaperType::kZv, 400, 0}, 1000, 256),
                      Catch::Contains("at least 2 are needed"));
    CHECK_THROWS_WITH(design_shaper_taps({ShaperType::kThreeHumpEi, 2, 0.1}, 10000, 4096),
                      Catch::Contains("the device remembers 4095"));
    CHECK_THROWS_AS(shaper_impulses({ShaperType::kMzv, 0, 0.1}), std::invalid_argument);
    CHECK_THROWS_AS(shaper_impulses({ShaperType::kMzv, 40, 1}), std::invalid_argument);
    CHECK_THROWS_AS(shaper_impulses({ShaperType::kMzv, NAN, 0.1}), std::invalid_argument);
}
