#include "pathstream/linux_device/paced_loop.hpp"

#include <algorithm>
#include <stdexcept>

namespace pathstream::linux_device {

std::uint64_t run_paced_loop(const std::function<void()>& tick,
                             const std::function<std::uint32_t()>& tick_hz,
                             const std::function<void(std::chrono::microseconds)>& serve,
                             const DeviceLoopOptions& options, const std::atomic<bool>& stop) {
    using clock = std::chrono::steady_clock;
    if (!(options.time_scale > 0)) throw std::invalid_argument("time scale must be positive");
    const auto begin = clock::now();
    std::uint64_t ticks = 0;
    double due_seconds = 0;  // tick k is due at begin + the sum of the tick periods before it
    while (!stop.load(std::memory_order_relaxed)) {
        const auto now = clock::now();
        if (options.run_for.count() > 0 && now - begin >= options.run_for) break;
        const double elapsed = std::chrono::duration<double>(now - begin).count();
        while (due_seconds <= elapsed) {
            tick();
            ++ticks;
            const std::uint32_t hz = tick_hz() != 0 ? tick_hz() : 1000;
            const double period = 1.0 / (hz * options.time_scale);
            due_seconds += period;
            // At rest, faster than rest_tick_hz: the next tick a rest period of wall time from
            // now, the idle ticks in between dropped (nothing happens in them to make up).
            if (options.at_rest && 1.0 / period > options.rest_tick_hz && options.at_rest()) {
                due_seconds = std::max(due_seconds, elapsed + 1.0 / options.rest_tick_hz);
                break;
            }
        }
        const double wait = due_seconds - elapsed;
        serve(std::chrono::microseconds(wait > 0 ? static_cast<long>(wait * 1e6) : 0));
    }
    return ticks;
}

}  // namespace pathstream::linux_device
