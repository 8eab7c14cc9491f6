// The simulated devices' pacing: ticks fall due on the steady clock at the time scale, and an
// idle device at rest ticks no more than the rest rate of wall time at any time scale (its CPU
// then does not grow with --time-scale). Only upper bounds on counts: a loaded machine runs
// fewer ticks, never more.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <thread>

#include "pathstream/linux_device/modbus_motion_device.hpp"

using namespace pathstream;
using namespace std::chrono_literals;

TEST_CASE("paced loop: at rest, ticks at most at the rest rate however fast the time scale",
          "[sim][pacing]") {
    std::atomic<bool> stop{false};
    std::uint64_t ticks = 0, serves = 0;
    linux_device::DeviceLoopOptions o;
    o.time_scale = 1000;  // 1 MHz of ticks at 1 kHz
    o.run_for = 200ms;
    o.at_rest = [] { return true; };
    o.rest_tick_hz = 1000;
    const std::uint64_t ran = linux_device::run_paced_loop([&] { ++ticks; }, [] { return 1000u; },
                                                           [&](std::chrono::microseconds w) {
                                                               ++serves;
                                                               std::this_thread::sleep_for(w);
                                                           },
                                                           o, stop);
    CHECK(ran == ticks);
    // 200 ms at 1,000 a second, with room for the first tick and the clock's rounding.
    CHECK(ticks <= 202);
    CHECK(ticks >= 1);
}

TEST_CASE("paced loop: a device that leaves rest is paced at its time scale again",
          "[sim][pacing]") {
    std::atomic<bool> stop{false};
    std::uint64_t ticks = 0, resting_serves = 0, long_running_waits = 0;
    bool resting = true;
    linux_device::DeviceLoopOptions o;
    o.time_scale = 1000;
    o.at_rest = [&] { return resting; };
    linux_device::run_paced_loop(
        [&] {
            ++ticks;
            if (ticks == 5) resting = false;  // a request arrived: no more rest
            if (ticks == 20005) stop.store(true);
        },
        [] { return 1000u; },
        [&](std::chrono::microseconds w) {
            if (resting) ++resting_serves;
            if (!resting && w >= 100us) ++long_running_waits;
            std::this_thread::sleep_for(w);
        },
        o, stop);
    CHECK(ticks >= 20005);  // the ticks already due when stop is set still run
    // At rest every tick is followed by a wait of the rest period; once it leaves rest no wait
    // is longer than a tick period (1 us at 1 MHz).
    // (A wait rounded down to the microsecond may need a second, zero-length one.)
    CHECK(resting_serves >= 4);
    CHECK(resting_serves <= 8);
    CHECK(long_running_waits == 0);
}
