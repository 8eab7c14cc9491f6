// A Modbus TCP device stays responsive while hostile clients hold connections: one dribbling a
// request a byte every 90 ms (just under the byte timeout) and a flood of connections that
// never send a request. A real stream beside them completes with no underrun and no
// reconnect, tick for tick as planned.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "stream_support.hpp"

using namespace pathstream;
using test::Job;
using test::plan_example;
using test::plan_setpoints;
using test::start_of;

namespace {

using Clock = std::chrono::steady_clock;
constexpr std::chrono::milliseconds kByteTimeout{250};

// A loopback TCP connection to `port`, or -1.
int connect_to(std::uint16_t port) {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    if (fd < 0) return -1;
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
        ::close(fd);
        return -1;
    }
    return fd;
}

// Sends FC4 "read the first status register" one byte every 90 ms, reads the reply, again,
// until stopped. Counts whole replies; `closed` when the server dropped it.
struct Slowloris {
    std::atomic<int> replies{0};
    std::atomic<bool> closed{false};
    std::atomic<bool> stop{false};
    std::thread thread;

    explicit Slowloris(std::uint16_t port) {
        thread = std::thread([this, port] {
            const int fd = connect_to(port);
            if (fd < 0) {
                closed = true;
                return;
            }
            const timeval tv{0, 200000};
            setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
            const std::uint8_t request[12] = {0, 1, 0, 0, 0, 6, 1, 4, 0, 0, 0, 1};
            while (!stop && !closed) {
                for (std::uint8_t b : request) {
                    if (stop) break;
                    std::this_thread::sleep_for(std::chrono::milliseconds(90));
                    if (::send(fd, &b, 1, MSG_NOSIGNAL) != 1) closed = true;
                }
                std::uint8_t reply[11];
                std::size_t got = 0;
                while (!stop && !closed && got < sizeof reply) {
                    const ssize_t n = ::recv(fd, reply + got, sizeof reply - got, 0);
                    if (n == 0) closed = true;
                    if (n > 0) got += static_cast<std::size_t>(n);
                }
                if (got == sizeof reply) ++replies;
            }
            ::close(fd);
        });
    }
    ~Slowloris() {
        stop = true;
        thread.join();
    }
};

// Opens connections that never send anything, 50 at a time, closing and reopening them in
// turn until stopped: the server's slots stay full of them.
struct Flood {
    std::atomic<int> opened{0};
    std::atomic<bool> stop{false};
    std::thread thread;

    explicit Flood(std::uint16_t port) {
        thread = std::thread([this, port] {
            std::vector<int> fds(50, -1);
            for (std::size_t i = 0; !stop; i = (i + 1) % fds.size()) {
                if (fds[i] >= 0) ::close(fds[i]);
                fds[i] = connect_to(port);
                if (fds[i] >= 0) ++opened;
                std::this_thread::sleep_for(std::chrono::milliseconds(5));
            }
            for (const int fd : fds) {
                if (fd >= 0) ::close(fd);
            }
        });
    }
    // Stops opening connections; after it, `opened` is final.
    void finish() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
    ~Flood() { finish(); }
};

// The device ticked and served on its own thread, real time; the longest gap between two
// ticks is kept for the figures (printed, never asserted).
struct DeviceThread {
    std::unique_ptr<linux_device::ModbusMotionDevice> device;
    std::unique_ptr<hal::ModbusServer> server;
    std::atomic<bool> stop{false};
    std::atomic<std::int64_t> longest_gap_us{0};
    std::thread thread;

    explicit DeviceThread(const std::vector<Lsb>& start) {
        device = linux_device::ModbusMotionDevice::create(start);
        device->record(true);
        // A byte timeout with room for a loaded machine's scheduling: the dribbler's 90 ms
        // gaps must stay under it even when its thread wakes late.
        hal::ModbusServerOptions options;
        options.byte_timeout = kByteTimeout;
        server = std::make_unique<hal::ModbusServer>(
            hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0}, options));
        thread = std::thread([this] {
            Clock::time_point last = Clock::now();
            linux_device::run_paced_loop(
                [&] {
                    const Clock::time_point now = Clock::now();
                    const auto gap =
                        std::chrono::duration_cast<std::chrono::microseconds>(now - last).count();
                    longest_gap_us = std::max<std::int64_t>(longest_gap_us, gap);
                    last = now;
                    device->tick();
                },
                [&] { return device->tick_hz(); },
                [&](std::chrono::microseconds w) { server->poll_once(w); }, {}, stop);
        });
    }
    ~DeviceThread() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
};

}  // namespace

TEST_CASE("a slow client and a connection flood do not disturb a stream",
          "[modbus][stream][threads]") {
    const Job job = plan_example("wave.json");
    DeviceThread dt(start_of(job.plan));
    const std::uint16_t port = dt.server->port();
    Slowloris slow(port);
    // The dribbler completes a request first: a client that has been served keeps its slot.
    const auto deadline = Clock::now() + std::chrono::seconds(10);
    while (slow.replies == 0 && !slow.closed && Clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    REQUIRE(slow.replies >= 1);
    Flood flood(port);
    host::StreamOptions o;
    o.target = "modbus-tcp://127.0.0.1:" + std::to_string(port) + "?unit=1";
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    // The dribbler's second reply takes about a second of 90 ms gaps, as long as the stream:
    // on a loaded machine its thread wakes late, so it is waited for (bounded) while the flood
    // goes on, rather than expected by the stream's end.
    const auto dribble_deadline = Clock::now() + std::chrono::seconds(15);
    while (slow.replies < 2 && !slow.closed && Clock::now() < dribble_deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    // A connect returns once the kernel has queued it, before the server's accept: stop the
    // flood, then give the still-serving device a bounded time to accept what was queued.
    flood.finish();
    const int flooded = flood.opened;
    const auto accept_deadline = Clock::now() + std::chrono::seconds(5);
    while (dt.server->counters().connections_accepted.load() <
               static_cast<std::uint64_t>(flooded) + 2 &&
           Clock::now() < accept_deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    const int dribbled = slow.replies;
    dt.stop = true;
    dt.thread.join();

    CHECK(report.underruns == 0);
    CHECK(report.reconnects == 0);
    CHECK(report.retries == 0);
    REQUIRE(report.ticks_executed == job.plan.total_ticks);
    const std::vector<Lsb> expected =
        plan_setpoints(job.plan, job.plan.spans.front().control.size());
    const std::vector<Lsb>& got = dt.device->recorded_setpoints();
    // Path ticks only: the job's end point is output by the tick that ends it, not a path tick.
    REQUIRE(got.size() == job.plan.total_ticks * job.plan.spans.front().control.size());
    for (std::size_t i = 0; i < got.size(); ++i) {
        INFO("value " << i);
        REQUIRE(got[i] == expected[i]);
    }
    CHECK(flooded > 50);  // the flood outnumbered the slots
    CHECK(dt.server->counters().connections_accepted.load() >=
          static_cast<std::uint64_t>(flooded) + 2);
    CHECK_FALSE(slow.closed);  // the dribbler, once served, was never evicted
    CHECK(dribbled >= 2);
    std::printf(
        "slow clients: stream %.2f s, %u underruns, %llu reconnects; %d flood connections; %d "
        "dribbled "
        "replies; longest gap between ticks %.1f ms\n",
        report.wall_seconds, report.underruns, static_cast<unsigned long long>(report.reconnects),
        flooded, dribbled, static_cast<double>(dt.longest_gap_us.load()) / 1000.0);
}

TEST_CASE("a frame stalled past the byte timeout closes only its connection", "[modbus][threads]") {
    const Lsb start[2] = {0, 0};
    DeviceThread dt({start[0], start[1]});
    const int fd = connect_to(dt.server->port());
    REQUIRE(fd >= 0);
    const std::uint8_t half[5] = {0, 1, 0, 0, 0};
    REQUIRE(::send(fd, half, sizeof half, MSG_NOSIGNAL) == 5);
    const timeval tv{5, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
    std::uint8_t byte = 0;
    CHECK(::recv(fd, &byte, 1, 0) == 0);  // closed by the server after the byte timeout, no reply
    ::close(fd);
    CHECK(dt.server->counters().bad_frames.load() == 1);
}
