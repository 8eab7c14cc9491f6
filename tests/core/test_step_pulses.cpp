// Step/dir generation (step_pulses.hpp): per tick the pulses equal the setpoint difference,
// sit where the closed form says, never come closer than floor(period / max steps) within a
// tick or across a boundary, and the direction changes only at a tick's start, before its
// first pulse. Seeded random setpoint walks, sized by --spans.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdint>
#include <random>
#include <vector>

#include "core/property_settings.hpp"
#include "pathstream/device/step_pulses.hpp"

using namespace pathstream::device;

namespace {

// Every pulse of a tick, by the schedule.
std::vector<std::uint32_t> pulses_of(StepSchedule& s) {
    std::vector<std::uint32_t> out;
    std::uint32_t offset = 0;
    while (s.next(offset)) out.push_back(offset);
    return out;
}

}  // namespace

TEST_CASE("step pulses sit at floor((2i + 1) period / (2 count)) for every small tick",
          "[device][step]") {
    for (std::uint32_t period = 1; period <= 160; ++period) {
        for (std::uint32_t count = 0; count <= period; ++count) {
            for (const bool negative : {false, true}) {
                const auto difference = static_cast<std::int32_t>(count) * (negative ? -1 : 1);
                StepSchedule s;
                REQUIRE(s.begin(period, difference));
                CHECK(s.forward() == (difference >= 0));
                const std::vector<std::uint32_t> p = pulses_of(s);
                REQUIRE(p.size() == count);
                for (std::uint32_t i = 0; i < count; ++i) {
                    const std::uint64_t expected =
                        (2ull * i + 1) * period / (2ull * static_cast<std::uint64_t>(count));
                    REQUIRE(p[i] == expected);
                    REQUIRE(p[i] < period);
                }
            }
        }
    }
}

TEST_CASE("step pulses of large periods and counts stay exact in 32 bits", "[device][step]") {
    const std::uint32_t period = 0x7FFFFFFFu;
    for (const std::uint32_t count : {1u, 3u, 1000u, 65535u, 1u << 20}) {
        StepSchedule s;
        REQUIRE(s.begin(period, -static_cast<std::int32_t>(count)));
        CHECK_FALSE(s.forward());
        std::uint32_t offset = 0, i = 0, last = 0;
        while (s.next(offset)) {
            const std::uint64_t expected = (2ull * i + 1) * period / (2ull * count);
            REQUIRE(offset == expected);
            last = offset;
            ++i;
        }
        CHECK(i == count);
        CHECK(last < period);
    }
}

TEST_CASE("a step schedule refuses what it cannot time", "[device][step]") {
    StepSchedule s;
    CHECK_FALSE(s.begin(0, 0));
    CHECK_FALSE(s.begin(0x80000000u, 1));
    CHECK_FALSE(s.begin(10, 11));
    CHECK_FALSE(s.begin(10, -11));
    CHECK_FALSE(s.begin(0x7FFFFFFFu, INT32_MIN));
    CHECK(s.left() == 0);
    std::uint32_t offset = 0;
    CHECK_FALSE(s.next(offset));
    CHECK(s.begin(10, -10));
    CHECK(s.left() == 10);

    CHECK(step_timing_check(0, 1, 0, 0) == StepTimingResult::kNoPeriod);
    CHECK(step_timing_check(0x80000000u, 1, 0, 0) == StepTimingResult::kPeriodTooLong);
    CHECK(step_timing_check(1000, 0, 0, 0) == StepTimingResult::kNoSteps);
    CHECK(step_timing_check(1000, 1001, 0, 0) == StepTimingResult::kTooManySteps);
    CHECK(step_timing_check(0x7FFFFFFFu, kMaxStepsPerTick + 1, 0, 0) ==
          StepTimingResult::kTooManySteps);
    // 1 kHz ticks on a 1 MHz timer: 1000 counts. 200 steps a tick are 5 us apart.
    CHECK(step_timing_check(1000, 200, 5, 2) == StepTimingResult::kOk);
    CHECK(step_timing_check(1000, 200, 6, 2) == StepTimingResult::kPulsesTooClose);
    CHECK(step_timing_check(1000, 200, 5, 3) == StepTimingResult::kDirSetupTooShort);
}

TEST_CASE("random setpoint walks: steps equal the differences and keep the driver's timing",
          "[device][step][property]") {
    std::mt19937_64 rng(pathstream::test::property_seed());
    const std::uint64_t ticks =
        std::max<std::uint64_t>(1000, pathstream::test::g_spans_per_basis / 4);
    for (const std::uint32_t period : {1000u, 997u, 168000u, 25u}) {
        for (const std::uint32_t max_steps : {1u, 7u, 25u}) {
            if (max_steps > period) continue;
            REQUIRE(step_timing_check(period, max_steps, period / max_steps,
                                      period / (2 * max_steps)) == StepTimingResult::kOk);
            std::uniform_int_distribution<int> draw(-static_cast<int>(max_steps),
                                                    static_cast<int>(max_steps));
            std::int64_t position = 0, setpoint = 0;
            std::uint64_t last_pulse = 0;
            bool have_pulse = false, level = true;
            std::uint64_t last_direction_change = 0;
            for (std::uint64_t t = 0; t < ticks; ++t) {
                // Runs of one direction and of rest as a real path has, with random turns.
                const int difference = (rng() % 8 == 0) ? 0 : draw(rng);
                setpoint += difference;
                StepSchedule s;
                REQUIRE(s.begin(period, difference));
                const std::uint64_t start = t * period;
                if (difference != 0 && s.forward() != level) {
                    level = s.forward();  // the direction output changes at the tick's start
                    last_direction_change = start;
                    if (have_pulse) REQUIRE(last_pulse < last_direction_change);
                }
                std::uint32_t offset = 0;
                bool first = true;
                while (s.next(offset)) {
                    const std::uint64_t at = start + offset;
                    if (first) REQUIRE(offset >= period / (2 * max_steps));
                    if (have_pulse) REQUIRE(at - last_pulse >= period / max_steps);
                    REQUIRE(at >= last_direction_change);
                    position += level ? 1 : -1;
                    last_pulse = at;
                    have_pulse = true;
                    first = false;
                }
                REQUIRE(position == setpoint);
            }
        }
    }
}

TEST_CASE("step pulse train: every axis's pulses come in groups, each at most a window early",
          "[device][step]") {
    constexpr unsigned kAxes = 4;
    std::mt19937_64 rng(pathstream::test::property_seed());
    const std::uint64_t ticks =
        std::max<std::uint64_t>(2000, pathstream::test::g_spans_per_basis / 50);
    std::uint64_t groups = 0;
    std::uint64_t pulses = 0;
    for (std::uint64_t t = 0; t < ticks; ++t) {
        const std::uint32_t period = std::uniform_int_distribution<std::uint32_t>(1, 100000)(rng);
        const std::uint32_t window = std::uniform_int_distribution<std::uint32_t>(0, 200)(rng);
        std::int32_t difference[kAxes];
        std::vector<std::uint32_t> scheduled[kAxes];
        for (unsigned a = 0; a < kAxes; ++a) {
            const auto most = static_cast<std::int32_t>(std::min<std::uint32_t>(period, 300));
            difference[a] = std::uniform_int_distribution<std::int32_t>(-most, most)(rng);
            StepSchedule s;
            REQUIRE(s.begin(period, difference[a]));
            scheduled[a] = pulses_of(s);
        }
        StepPulseTrain<kAxes> train;
        REQUIRE(train.begin(period, difference));
        for (unsigned a = 0; a < kAxes; ++a)
            CHECK(((train.forward_mask() >> a) & 1u) == (difference[a] >= 0 ? 1u : 0u));
        std::vector<std::uint32_t> got[kAxes];
        std::uint32_t offset = 0;
        std::uint32_t mask = 0;
        std::uint32_t last = 0;
        while (train.next(window, offset, mask)) {
            REQUIRE(mask != 0);
            REQUIRE(offset >= last);  // groups in time order
            last = offset;
            ++groups;
            for (unsigned a = 0; a < kAxes; ++a)
                if ((mask >> a) & 1u) got[a].push_back(offset);
        }
        CHECK(train.left() == 0);
        for (unsigned a = 0; a < kAxes; ++a) {
            // As many pulses as the difference, each at most `window` before its schedule.
            REQUIRE(got[a].size() == scheduled[a].size());
            for (std::size_t i = 0; i < got[a].size(); ++i) {
                REQUIRE(got[a][i] <= scheduled[a][i]);
                REQUIRE(scheduled[a][i] - got[a][i] <= window);
            }
            pulses += got[a].size();
        }
    }
    CHECK(groups <= pulses);
}

TEST_CASE("step pulse train: a difference out of bounds schedules nothing on any axis",
          "[device][step]") {
    StepPulseTrain<3> train;
    const std::int32_t fine[3] = {5, -7, 0};
    REQUIRE(train.begin(100, fine));
    CHECK(train.left() == 12);
    const std::int32_t too_many[3] = {5, 101, 3};  // more steps than counts in the tick
    CHECK_FALSE(train.begin(100, too_many));
    CHECK(train.left() == 0);
    std::uint32_t offset = 0, mask = 0;
    CHECK_FALSE(train.next(0, offset, mask));
}
