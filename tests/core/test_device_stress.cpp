// The device under stress: a task side sending random valid and invalid batches (some ending
// in a programmed pause, kWirePause, that a later resume leaves; some pausing while moving,
// refused), commands, faults, e-stops and resets at random moments, and a tick side checked on
// every tick (steps and second differences within the limits, generated moves included; no motion
// in idle, fault or e-stop; no span of an older epoch executed; the pen up on every tick that is
// not a path tick; the status never torn). Two ways:
//   - two threads, the tick as fast as it can (tag [threads]: the ThreadSanitizer preset
//     runs it too);
//   - one thread, the tick run at seeded points between and inside the task side's calls
//     (accept_batch's interleaving hook), so a failure reproduces from its seed.
// Size: core_tests --stress-ticks N (default 1,000,000 each); seed: --rng-seed S.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <random>
#include <thread>

#include "core/device_stress.hpp"
#include "core/property_settings.hpp"

using namespace pathstream;
using namespace pathstream::test::stress;
using pathstream::test::g_stress_ticks;
using pathstream::test::property_seed;

namespace {

// The activity a run must show, so that the invariants were exercised at all.
void check_coverage(const TickChecker& c, const DriverCounts& n, std::uint64_t ticks) {
    INFO("path ticks " << c.path_ticks() << ", epochs " << c.epochs() << ", jobs finished "
                       << c.jobs_finished() << ", batches ok " << n.batches_ok << ", refused "
                       << n.batches_refused << ", invalid refused " << n.invalid_refused
                       << ", actions " << n.actions);
    CHECK(c.ticks() >= ticks);
    CHECK(c.path_ticks() > 10000);
    CHECK(c.epochs() > 10);
    CHECK(c.jobs_finished() > 0);
    CHECK(n.batches_ok > 100);
    CHECK(n.invalid_refused > 10);
    CHECK(n.pauses_sent > 0);
    CHECK(c.paused_ticks() > 0);
    CHECK(c.pauses_resumed() > 0);
}

void print_summary(const char* name, std::uint64_t seed, const TickChecker& c,
                   const DriverCounts& n, std::uint32_t underruns, std::uint64_t generated) {
    std::printf(
        "%s: seed %llu, %llu ticks (%llu path, %llu generated), %llu epochs, %llu jobs finished, "
        "%u underruns, "
        "%llu batches accepted (%llu spans), %llu refused, %llu invalid refused, %llu commands, "
        "%llu faults, "
        "%llu e-stops, %llu pauses sent (%llu ticks paused, %llu resumed)\n",
        name, static_cast<unsigned long long>(seed), static_cast<unsigned long long>(c.ticks()),
        static_cast<unsigned long long>(c.path_ticks()), static_cast<unsigned long long>(generated),
        static_cast<unsigned long long>(c.epochs()),
        static_cast<unsigned long long>(c.jobs_finished()), underruns,
        static_cast<unsigned long long>(n.batches_ok), static_cast<unsigned long long>(n.spans_ok),
        static_cast<unsigned long long>(n.batches_refused),
        static_cast<unsigned long long>(n.invalid_refused),
        static_cast<unsigned long long>(n.commands), static_cast<unsigned long long>(n.faults),
        static_cast<unsigned long long>(n.estops), static_cast<unsigned long long>(n.pauses_sent),
        static_cast<unsigned long long>(c.paused_ticks()),
        static_cast<unsigned long long>(c.pauses_resumed()));
    std::printf(
        "  ticks per state: idle %llu, running %llu, holding %llu, stopping %llu, fault %llu, "
        "e-stop %llu\n",
        static_cast<unsigned long long>(c.ticks_in(device::DeviceState::kIdle)),
        static_cast<unsigned long long>(c.ticks_in(device::DeviceState::kRunning)),
        static_cast<unsigned long long>(c.ticks_in(device::DeviceState::kHolding)),
        static_cast<unsigned long long>(c.ticks_in(device::DeviceState::kStopping)),
        static_cast<unsigned long long>(c.ticks_in(device::DeviceState::kFault)),
        static_cast<unsigned long long>(c.ticks_in(device::DeviceState::kEstop)));
}

}  // namespace

TEST_CASE(
    "device stress: random batches, commands, faults and e-stops against a free-running tick "
    "(threads)",
    "[device][stress][threads]") {
    const std::uint64_t ticks = g_stress_ticks;
    const std::uint64_t seed = property_seed();
    INFO("seed " << seed << ", " << ticks << " ticks");
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    constexpr std::size_t kKeep = 1u << 22;  // setpoints kept for the torn-read comparison
    TickChecker checker(static_cast<std::size_t>(std::min<std::uint64_t>(ticks, kKeep)));
    // The tick runs flat out for at least `ticks` ticks and until the task side has acted
    // kMinActions times.
    constexpr std::uint64_t kMinActions = 20000;
    std::atomic<bool> done{false};
    std::atomic<std::uint64_t> actions{0};
    // The tick count of the task side's last action: the ticker never runs more than
    // kMaxLead ticks past it, so a starved task thread (a loaded machine, one core) cannot
    // leave the whole run to the tick alone; the two still run at once, in any interleaving.
    constexpr std::uint64_t kMaxLead = 400;
    std::atomic<std::uint64_t> task_mark{0};
    std::thread ticker([&] {
        for (std::uint64_t k = 0;
             k < ticks || actions.load(std::memory_order_relaxed) < kMinActions; ++k) {
            while (k > task_mark.load(std::memory_order_acquire) + kMaxLead)
                std::this_thread::yield();
            Lsb out[kAxes];
            d.tick(out);
            checker.after_tick(d.status());
        }
        done.store(true);
    });
    Driver driver(d, seed);
    std::mt19937 gaps(static_cast<std::uint32_t>(seed));
    std::uint32_t last_action = 0;
    while (!done.load()) {
        // Each action waits for 0 to 40 ticks after the last one (at random): on a loaded
        // machine, where the two threads often run in turns rather than at once, the task side
        // then never piles up thousands of actions against one tick, nor the reverse.
        const std::uint32_t until =
            last_action + std::uniform_int_distribution<std::uint32_t>(0, 40)(gaps);
        while (!done.load() && static_cast<std::int32_t>(d.status().tick_count - until) < 0)
            std::this_thread::yield();
        last_action = d.status().tick_count;
        driver.step(device::NoInterleave{});
        actions.store(driver.counts().actions, std::memory_order_relaxed);
        task_mark.store(d.status().tick_count, std::memory_order_release);
    }
    ticker.join();
    INFO(checker.failure());
    REQUIRE(checker.ok());
    INFO(driver.failure());
    REQUIRE(driver.failure().empty());
    // Every status the task side read was one tick's, whole.
    std::size_t compared = 0;
    for (const Driver::Sample& s : driver.samples()) {
        if (std::size_t{s.tick} * kAxes >= checker.positions().size()) continue;
        ++compared;
        for (unsigned a = 0; a < kAxes; ++a) {
            INFO("status of tick " << s.tick);
            REQUIRE(s.position[a] == checker.positions()[s.tick * kAxes + a]);
        }
    }
    CHECK(compared > 100);
    const Status3 last = d.status();
    print_summary("device stress, two threads", seed, checker, driver.counts(), last.underruns,
                  last.generated_ticks());
    check_coverage(checker, driver.counts(), ticks);
}

TEST_CASE("device stress: the same, on one thread, the tick interleaved at seeded points",
          "[device][stress]") {
    const std::uint64_t ticks = g_stress_ticks;
    const std::uint64_t seed = property_seed();
    INFO("seed " << seed << ", " << ticks << " ticks: reproduce with --rng-seed " << seed);
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(limits()) == Status::kOk);
    TickChecker checker;
    std::mt19937_64 points(seed ^ 0x9E3779B97F4A7C15ull);
    auto run_ticks = [&](int count) {
        for (int i = 0; i < count && checker.ticks() < ticks; ++i) {
            Lsb out[kAxes];
            d.tick(out);
            checker.after_tick(d.status());
        }
    };
    // Inside accept_batch: before a span is queued, sometimes a few ticks (the interrupt).
    auto between = [&] {
        if (std::uniform_int_distribution<int>(0, 3)(points) == 0) {
            run_ticks(std::uniform_int_distribution<int>(1, 12)(points));
        }
    };
    Driver driver(d, seed);
    while (checker.ticks() < ticks && checker.ok() && driver.failure().empty()) {
        driver.step(between);
        run_ticks(std::uniform_int_distribution<int>(0, 60)(points));
    }
    INFO(checker.failure());
    REQUIRE(checker.ok());
    INFO(driver.failure());
    REQUIRE(driver.failure().empty());
    const Status3 last = d.status();
    print_summary("device stress, one thread", seed, checker, driver.counts(), last.underruns,
                  last.generated_ticks());
    check_coverage(checker, driver.counts(), ticks);
}
