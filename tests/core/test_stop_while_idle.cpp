// A stop sent while the device is idle drops its (empty) queue: a new epoch, taken by the next
// tick. A host that waits for that epoch must never wait longer than the device's clock says.
// Two ways, with one bound: the status read right after posting shows tick T; tick T + 1 may
// have read the mailbox before the post (it was already running), so tick T + 2 is the last
// that may publish the new epoch. Each stop advances the epoch by exactly one.
//   - two real threads, the tick paced at 1 kHz on a steady clock (never two ticks back to
//     back, as an interrupt) and the machine loaded by one busy thread per core (tag [threads]: the
//     ThreadSanitizer preset runs it too);
//   - one thread, posts, ticks and status reads in a seeded order (--rng-seed S).
// Size: core_tests --stress-ticks N (stops: N / 1000, at least 200).
#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

#include "core/property_settings.hpp"
#include "pathstream/device/motion_device.hpp"

namespace pathstream::test {
extern std::uint64_t g_stress_ticks;  // core_tests --stress-ticks N (test_main.cpp)
}

using namespace pathstream;
using pathstream::test::g_stress_ticks;
using pathstream::test::property_seed;

namespace {

constexpr unsigned kAxes = 2;
using Device = device::MotionDevice<kAxes, 16>;

device::MotionLimits<kAxes> limits() {
    device::MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (unsigned a = 0; a < kAxes; ++a) l.axis[a] = {100000, 2000000};
    return l;
}

std::uint32_t stop_count() {
    return static_cast<std::uint32_t>(std::max<std::uint64_t>(200, g_stress_ticks / 1000));
}

// One stop's record: the tick the post was seen after, and the first tick showing its epoch.
struct StopRecord {
    std::uint32_t posted_after_tick = 0;
    std::uint32_t epoch_tick = 0;
    std::uint32_t epoch_before = 0;
    std::uint32_t epoch_after = 0;
};

// A stop's delay: from the tick the status read right after the post showed, to the first tick
// that published its epoch. At most 2 (see the top); 0 or less when the task was preempted
// between the post and that read and the epoch was already out.
void check_records(const std::vector<StopRecord>& records) {
    for (std::size_t i = 0; i < records.size(); ++i) {
        const StopRecord& r = records[i];
        INFO("stop " << i << ": posted after tick " << r.posted_after_tick << ", epoch "
                     << r.epoch_before << " -> " << r.epoch_after << " at tick " << r.epoch_tick);
        REQUIRE(r.epoch_after == r.epoch_before + 1u);
        REQUIRE(std::int64_t{r.epoch_tick} - std::int64_t{r.posted_after_tick} <= 2);
    }
}

}  // namespace

TEST_CASE(
    "stop while idle: every stop advances the epoch by one within the next tick, loaded scheduler",
    "[device][threads]") {
    const Lsb start[kAxes] = {0, 0};
    Device device(start);
    REQUIRE(device.configure(limits()) == Status::kOk);
    const std::uint32_t stops = stop_count();

    // The tick thread records each epoch change (the tick that first published it), in storage
    // it alone writes and sized by the stops, not by the wall time a starved task takes; the
    // task side reads it only after joining.
    struct EpochChange {
        std::uint32_t tick = 0;
        std::uint32_t epoch = 0;
    };
    std::vector<EpochChange> changes(std::size_t{stops} + 1);
    std::size_t change_count = 0;
    std::atomic<bool> overflow{false};
    std::atomic<bool> done{false};
    // One busy thread per core beside the two under test: the scheduler must preempt them.
    std::vector<std::thread> hogs;
    const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
    for (unsigned i = 0; i < cores; ++i) {
        hogs.emplace_back([&done] {
            volatile std::uint64_t spin = 0;
            while (!done.load(std::memory_order_relaxed)) spin = spin + 1;
        });
    }
    std::thread ticker([&] {
        using Clock = std::chrono::steady_clock;
        auto next = Clock::now();
        std::uint32_t last_epoch = device.epoch();
        Lsb out[kAxes];
        while (!done.load(std::memory_order_acquire)) {
            device.tick(out);
            const device::DeviceStatus<kAxes> s = device.status();
            if (s.epoch != last_epoch) {
                if (change_count == changes.size()) {
                    overflow.store(true, std::memory_order_relaxed);  // more epochs than stops
                    return;
                }
                changes[change_count++] = {s.tick_count, s.epoch};
                last_epoch = s.epoch;
            }
            // Paced like a tick interrupt, which never runs two ticks back to back: a thread
            // catching up after starvation would, and two ticks could then both fall inside
            // the moment in which the other core's post is not yet visible to this one (a
            // store still in its store buffer), which no bound in ticks survives.
            next = std::max(next + std::chrono::milliseconds(1),
                            Clock::now() + std::chrono::microseconds(200));
            std::this_thread::sleep_until(next);
        }
    });

    std::vector<StopRecord> records;
    records.reserve(stops);
    std::uint64_t waits = 0;
    bool refused = false;
    for (std::uint32_t i = 0; i < stops && !overflow.load(std::memory_order_relaxed); ++i) {
        StopRecord r;
        r.epoch_before = device.epoch();
        if (device.state() != device::DeviceState::kIdle ||
            device.command(device::Command::kStop) != Status::kOk) {
            refused = true;
            break;
        }
        r.posted_after_tick = device.status().tick_count;
        // Waits in device ticks, not in wall time: a starved tick thread only makes it longer.
        bool late = false;
        for (;;) {
            const device::DeviceStatus<kAxes> s = device.status();
            if (s.epoch != r.epoch_before) break;
            if (s.tick_count - r.posted_after_tick > 2u) {
                late = true;  // the tick after next published the old epoch still
                break;
            }
            ++waits;
            std::this_thread::yield();
        }
        records.push_back(r);
        if (late) break;  // check_records names it, with the tick it became visible at
    }
    done.store(true, std::memory_order_release);
    ticker.join();
    for (std::thread& h : hogs) h.join();
    INFO(records.size() << " stops, " << waits << " status reads while waiting, " << change_count
                        << " epoch changes");
    REQUIRE_FALSE(refused);
    REQUIRE_FALSE(overflow.load());
    // Each stop makes exactly one epoch change, in order (a late stop's change came after the
    // task stopped waiting, while the tick thread still ran).
    REQUIRE(change_count >= records.size());
    for (std::size_t i = 0; i < records.size(); ++i) {
        records[i].epoch_tick = changes[i].tick;
        records[i].epoch_after = changes[i].epoch;
    }
    check_records(records);
    REQUIRE(records.size() == stops);
    REQUIRE(change_count == stops);
}

TEST_CASE("stop while idle: posts, ticks and status reads in a seeded order", "[device]") {
    const std::uint64_t seed = property_seed();
    std::mt19937_64 rng(seed);
    INFO("seed " << seed);
    const Lsb start[kAxes] = {0, 0};
    Device device(start);
    REQUIRE(device.configure(limits()) == Status::kOk);
    Lsb out[kAxes];

    // On one thread no tick is ever in progress at a post: the very next tick must take it.
    std::vector<StopRecord> records;
    const std::uint32_t stops = stop_count();
    std::uint32_t ticks_between = 0;
    for (std::uint32_t i = 0; i < stops; ++i) {
        for (std::uint32_t k = static_cast<std::uint32_t>(rng() % 4); k > 0; --k) device.tick(out);
        StopRecord r;
        r.epoch_before = device.epoch();
        // Repeated stops in one tick: the last replaces the others, and one epoch follows.
        const std::uint32_t repeats = 1 + static_cast<std::uint32_t>(rng() % 3);
        for (std::uint32_t k = 0; k < repeats; ++k)
            REQUIRE(device.command(device::Command::kStop) == Status::kOk);
        r.posted_after_tick = device.status().tick_count;
        CHECK(device.command_pending());
        while (device.epoch() == r.epoch_before) {
            REQUIRE(device.status().tick_count - r.posted_after_tick < 2u);
            device.tick(out);
            ++ticks_between;
        }
        r.epoch_after = device.epoch();
        r.epoch_tick = device.status().tick_count;
        CHECK_FALSE(device.command_pending());
        records.push_back(r);
    }
    check_records(records);
    // Single-threaded, no tick is ever in progress at a post: the very next tick takes it.
    for (const StopRecord& r : records) CHECK(r.epoch_tick == r.posted_after_tick + 1u);
    CHECK(ticks_between == stops);
}
