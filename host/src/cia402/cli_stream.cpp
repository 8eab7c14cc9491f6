// The CLI's CiA 402 branch: stream a plan to CSP drives and print what happened.
#include <chrono>
#include <cstdio>
#include <thread>

#include "pathstream/host/cia402_master.hpp"
#include "pathstream/host/progress.hpp"

namespace pathstream::host {
namespace {

std::int64_t steady_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch())
        .count();
}

// Bits of a CAN 2.0A frame with n data bytes: 47 + 8n, plus one stuff bit per 5 of the 34 + 8n
// stuffed bits. Slightly below can::frame_bits_worst_case (a stuff bit every 4 bits after the
// first 5), which the native streamer and bench_can count: docs/cia402.md "Bus load per cycle".
unsigned worst_case_bits(unsigned n) {
    return (269 + 48 * n) / 5;
}

}  // namespace

SteadyMicrosecondClock::SteadyMicrosecondClock() : start_ns_(steady_ns()) {}

std::uint64_t SteadyMicrosecondClock::now() const {
    return static_cast<std::uint64_t>((steady_ns() - start_ns_) / 1000);
}

void SteadyMicrosecondClock::wait_until(std::uint64_t tick) {
    const std::uint64_t t = now();
    if (tick > t) std::this_thread::sleep_for(std::chrono::microseconds(tick - t));
}

int run_cia402_stream(const Plan& plan, const MachineProfile& profile, const std::string& target,
                      hal::CanBus& bus) {
    const Cia402Target t = parse_cia402_target(target, profile.axes.size());
    SteadyMicrosecondClock clock;
    Cia402Report r;
    {
        ProgressBar bar("streaming");
        r = stream_cia402(plan, profile, t.options, bus, clock, [&](double f) { bar.update(f); });
    }
    const std::size_t axes = profile.axes.size();
    // Per cycle: an RPDO1 (6 bytes) per drive [+ RPDO2: 4, 6 with the torque offset], one
    // SYNC, a TPDO1 (6) per drive [+ TPDO2 (4)].
    const Cia402FeedForward ff = t.options.feed_forward;
    const unsigned rpdo2 = ff == Cia402FeedForward::kNone       ? 0
                           : ff == Cia402FeedForward::kVelocity ? worst_case_bits(4)
                                                                : worst_case_bits(6);
    const unsigned bits =
        worst_case_bits(0) +
        static_cast<unsigned>(axes) *
            (2 * worst_case_bits(6) + rpdo2 + (t.options.demand_echo ? worst_case_bits(4) : 0));
    std::printf("streamed      %s (CiA 402 CSP, %u ms cycle, feed-forward %s, nodes",
                target.c_str(), t.options.cycle_ms, cia402_feed_forward_name(ff));
    for (const auto n : t.options.nodes) std::printf(" %u", unsigned(n));
    std::printf(")\n");
    std::printf("executed      %llu motion cycles (%llu path ticks), %llu cycles in all\n",
                static_cast<unsigned long long>(r.motion_cycles),
                static_cast<unsigned long long>(r.path_ticks),
                static_cast<unsigned long long>(r.cycles));
    std::printf("final point  ");
    for (std::size_t a = 0; a < axes; ++a) {
        std::printf(" %s %.4f mm", profile.axes[a].name.c_str(),
                    r.final_position[a] * profile.mm_per_lsb);
    }
    std::printf(
        "\nbus           %llu frames sent, %llu received, %llu cycles without feedback, %llu lost "
        "RPDOs seen;"
        " %u bits worst case per cycle (%.1f %% of 1 Mbit/s)\n",
        static_cast<unsigned long long>(r.frames_sent),
        static_cast<unsigned long long>(r.frames_received),
        static_cast<unsigned long long>(r.missed_feedback),
        static_cast<unsigned long long>(r.demand_mismatches), bits,
        bits / (t.options.cycle_ms * 10.0));
    std::printf(
        "drives        largest step %d LSB per cycle, largest lag (following error) %d LSB = "
        "%.4f mm; wall time %.2f s\n",
        r.max_step, r.max_lag, r.max_lag * profile.mm_per_lsb, r.wall_seconds);
    return 0;
}

}  // namespace pathstream::host
