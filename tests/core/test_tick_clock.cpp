// Ticks from a free-running counter (tick_clock.hpp): over any pattern of interrupt entries
// (late, lost, bunched, across the counter's 32-bit wrap) the ticks run equal the whole
// periods elapsed, never more per call than asked, the backlog is bounded and its overflow
// counted, and a change of rate keeps the elapsed fraction of a period. Seeded, sized by
// --spans.
#include <catch2/catch.hpp>
#include <cstdint>
#include <random>

#include "core/property_settings.hpp"
#include "pathstream/device/tick_clock.hpp"

using pathstream::device::TickClock;

TEST_CASE("tick clock: one tick per period of the counter, the first one period after start",
          "[device][tick_clock]") {
    TickClock c;
    REQUIRE(c.start(1000000000u, 1000u, 5u));
    CHECK(c.advance(5u + 999999u, 10) == 0);
    CHECK(c.advance(5u + 1000000u, 10) == 1);
    CHECK(c.advance(5u + 1999999u, 10) == 0);
    CHECK(c.advance(5u + 5000000u, 10) == 4);
    // At most max_ticks per call; the rest stay owed.
    CHECK(c.advance(5u + 15000000u, 3) == 3);
    CHECK(c.advance(5u + 15000000u, 100) == 7);
    CHECK(c.dropped() == 0);
    // Refused settings change nothing.
    CHECK_FALSE(c.start(1000u, 0u, 0u));
    CHECK_FALSE(c.start(999u, 1000u, 0u));
    CHECK_FALSE(c.retune(2000000000u, 0u));
    CHECK(c.tick_hz() == 1000u);
}

TEST_CASE("tick clock: ticks equal the whole periods elapsed over random entries and wraps",
          "[device][tick_clock]") {
    std::mt19937_64 rng(pathstream::test::property_seed());
    const std::uint64_t rounds =
        std::max<std::uint64_t>(20, pathstream::test::g_spans_per_basis / 5000);
    for (std::uint64_t round = 0; round < rounds; ++round) {
        const std::uint32_t counter_hz =
            std::uniform_int_distribution<std::uint32_t>(1000u, 1000000000u)(rng);
        const std::uint32_t tick_hz =
            std::uniform_int_distribution<std::uint32_t>(1u, std::min(counter_hz, 100000u))(rng);
        const std::uint32_t start = static_cast<std::uint32_t>(rng());
        TickClock c;
        REQUIRE(c.start(counter_hz, tick_hz, start));
        // Entries at random gaps of up to ten periods (a lost interrupt, a late one), the
        // counter wrapping many times; the exact count is floor(elapsed * tick_hz / counter_hz).
        const std::uint64_t period = counter_hz / tick_hz;
        std::uint64_t elapsed = 0;
        std::uint64_t ran = 0;
        for (int entry = 0; entry < 2000; ++entry) {
            const std::uint64_t gap =
                std::uniform_int_distribution<std::uint64_t>(0, 10 * period + 10)(rng);
            elapsed += gap;
            ran += c.advance(static_cast<std::uint32_t>(start + elapsed), 1000);
            const std::uint64_t exact = static_cast<std::uint64_t>(
                (static_cast<unsigned __int128>(elapsed) * tick_hz) / counter_hz);
            REQUIRE(ran == exact);
        }
        CHECK(c.dropped() == 0);
    }
}

TEST_CASE("tick clock: a backlog beyond the limit is dropped and counted, never run at once",
          "[device][tick_clock]") {
    TickClock c;
    REQUIRE(c.start(1000000u, 1000u, 0u));
    // 4,000 periods without an entry (the counter read less often than it should be).
    std::uint32_t now = 4000u * 1000u;
    std::uint32_t run = c.advance(now, 10);
    CHECK(run == 10);
    CHECK(c.dropped() == 4000u - TickClock::kMaxBacklog);
    std::uint32_t total = run;
    while ((run = c.advance(now, 64)) != 0) total += run;
    CHECK(total == TickClock::kMaxBacklog);
}

TEST_CASE("tick clock: a new rate keeps the elapsed fraction of a period", "[device][tick_clock]") {
    TickClock c;
    REQUIRE(c.start(1000000u, 1000u, 0u));  // period 1000 counts
    CHECK(c.advance(2500u, 10) == 2);       // half a period elapsed
    REQUIRE(c.retune(100u, 2500u));         // period 10,000 counts: half of it is 5,000
    CHECK(c.advance(2500u + 4999u, 10) == 0);
    CHECK(c.advance(2500u + 5000u, 10) == 1);
    CHECK(c.advance(2500u + 15000u, 10) == 1);
    CHECK(c.tick_hz() == 100u);
}
