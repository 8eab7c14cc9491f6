#include "pathstream/hal/linux_clock.hpp"

#include <cerrno>
#include <cmath>
#include <stdexcept>

namespace pathstream::hal {
namespace {

constexpr std::int64_t kNanosPerSecond = 1'000'000'000;

std::int64_t to_nanos(const timespec& t) {
    return static_cast<std::int64_t>(t.tv_sec) * kNanosPerSecond + t.tv_nsec;
}

}  // namespace

LinuxClock::LinuxClock(double tick_hz) : tick_hz_(tick_hz) {
    if (!(tick_hz > 0) || !std::isfinite(tick_hz)) {
        throw std::invalid_argument("LinuxClock: the tick rate must be a positive number of Hz");
    }
    clock_gettime(CLOCK_MONOTONIC, &start_);
}

std::uint64_t LinuxClock::now() const {
    timespec t{};
    clock_gettime(CLOCK_MONOTONIC, &t);
    const std::int64_t elapsed = to_nanos(t) - to_nanos(start_);
    if (elapsed <= 0) return 0;
    return static_cast<std::uint64_t>(std::floor(static_cast<double>(elapsed) * tick_hz_ / 1e9));
}

void LinuxClock::wait_until(std::uint64_t tick) {
    // Deadline = start + tick / tick_hz, rounded up to the nanosecond so that now() >= tick
    // holds on return.
    const double offset = std::ceil(static_cast<double>(tick) * 1e9 / tick_hz_);
    const std::int64_t deadline = to_nanos(start_) + static_cast<std::int64_t>(offset);
    timespec at{};
    at.tv_sec = static_cast<time_t>(deadline / kNanosPerSecond);
    at.tv_nsec = static_cast<long>(deadline % kNanosPerSecond);
    while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &at, nullptr) == EINTR) {
    }
    while (now() < tick) {  // floating-point edge: spin the last nanoseconds
    }
}

}  // namespace pathstream::hal
