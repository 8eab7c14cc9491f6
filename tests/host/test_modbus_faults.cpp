// Modbus streaming under faults, end to end (simulated device thread + hal::ModbusServer +
// host::stream_modbus): a TCP connection cut mid-frame, a noisy RTU line, a device restarted
// mid-stream, a queue run dry, and dead peers. Every run is seeded or cut at a fixed frame, so
// each is deterministic; every wait is bounded.
#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "pathstream/device/modbus_map.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/hal/pseudo_terminal.hpp"
#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/span.hpp"
#include "stream_support.hpp"

using namespace pathstream;
using Catch::Matchers::Contains;
using test::Job;
using test::plan_example;
using test::plan_setpoints;
using test::start_of;
using SteadyClock = std::chrono::steady_clock;

namespace {

namespace st = device::modbus::status;

// The device's recorded path ticks are the plan's setpoints, tick for tick, every span once.
void check_executed(const Job& job, const linux_device::ModbusMotionDevice& device,
                    const host::StreamReport& report) {
    const std::size_t axes = job.plan.spans.front().control.size();
    const std::vector<Lsb> expected = plan_setpoints(job.plan, axes);
    const std::vector<Lsb>& got = device.recorded_setpoints();
    REQUIRE(report.last_completed == job.plan.spans.size());
    REQUIRE(report.ticks_executed == job.plan.total_ticks);
    REQUIRE(got.size() == job.plan.total_ticks * axes);
    for (std::size_t i = 0; i < got.size(); ++i) {
        INFO("tick " << i / axes << " axis " << i % axes);
        REQUIRE(got[i] == expected[i]);
    }
    for (std::size_t a = 0; a < axes; ++a)
        CHECK(report.final_position[a] == expected[expected.size() - axes + a]);
}

// A status register of a device, read from the thread that serves it (no Catch assertions
// here: they are not thread-safe; a bad address reads as 0xFFFF, which no check expects).
std::uint16_t status_u16(linux_device::ModbusMotionDevice& d, std::uint16_t reg) {
    std::uint16_t r = 0;
    if (d.handler().read_input_registers(reg, 1, &r) != hal::ModbusException::kNone) return 0xFFFF;
    return r;
}
std::uint32_t status_u32(linux_device::ModbusMotionDevice& d, std::uint16_t reg) {
    std::uint16_t r[2] = {};
    if (d.handler().read_input_registers(reg, 2, r) != hal::ModbusException::kNone)
        return 0xFFFFFFFFu;
    return (static_cast<std::uint32_t>(r[0]) << 16) | r[1];
}

// A thread joined on destruction; `stop` ends its loop.
struct Runner {
    std::atomic<bool> stop{false};
    std::thread thread;
    void join() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
    ~Runner() { join(); }
};

// Serves `server` and ticks `device` until stopped (the plain device of test_modbus_stream).
void run_device(Runner& r, linux_device::ModbusMotionDevice& device, hal::ModbusServer& server,
                double time_scale) {
    r.thread = std::thread([&r, &device, &server, time_scale] {
        linux_device::DeviceLoopOptions o;
        o.time_scale = time_scale;
        linux_device::run_device_loop(
            device, [&](std::chrono::microseconds w) { server.poll_once(w); }, o, r.stop);
    });
}

std::string tcp_target(std::uint16_t port) {
    return "modbus-tcp://127.0.0.1:" + std::to_string(port) + "?unit=1";
}

int tcp_socket() {
    const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    REQUIRE(fd >= 0);
    return fd;
}

sockaddr_in loopback(std::uint16_t port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    return a;
}

// A listening socket on an ephemeral loopback port that never accepts: the kernel completes
// the handshake from the backlog, so a client connects and then hears nothing.
struct SilentListener {
    int fd = -1;
    std::uint16_t port = 0;
    SilentListener() {
        fd = tcp_socket();
        sockaddr_in a = loopback(0);
        REQUIRE(::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
        REQUIRE(::listen(fd, 8) == 0);
        socklen_t len = sizeof a;
        REQUIRE(::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) == 0);
        port = ntohs(a.sin_port);
    }
    ~SilentListener() { ::close(fd); }
};

// A TCP forwarder between the host and the device's server that cuts the connection once, in
// the middle of a chosen frame: the `fc23_index`-th FC23 request (the batch never reaches the
// device) or response (the device applied the batch but the host never hears so). It forwards
// whole MBAP frames (6 + length bytes), so it can count them.
class TcpCutProxy {
public:
    enum class Cut { kRequest, kResponse };

    TcpCutProxy(std::uint16_t upstream, Cut cut, int fc23_index)
        : upstream_(upstream), cut_(cut), index_(fc23_index) {
        listen_ = tcp_socket();
        sockaddr_in a = loopback(0);
        REQUIRE(::bind(listen_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
        REQUIRE(::listen(listen_, 8) == 0);
        socklen_t len = sizeof a;
        REQUIRE(::getsockname(listen_, reinterpret_cast<sockaddr*>(&a), &len) == 0);
        port_ = ntohs(a.sin_port);
        runner_.thread = std::thread([this] { run(); });
    }
    ~TcpCutProxy() {
        runner_.join();
        close_pair();
        ::close(listen_);
    }

    std::uint16_t port() const { return port_; }
    int cuts() const { return cuts_.load(); }
    int accepted() const { return accepted_.load(); }

private:
    struct Direction {
        std::vector<std::uint8_t> pending;
        int fc23 = 0;
    };

    void close_pair() {
        if (client_ >= 0) ::close(client_);
        if (server_ >= 0) ::close(server_);
        client_ = server_ = -1;
        requests_ = responses_ = Direction{};
    }

    static bool send_all(int fd, const std::uint8_t* p, std::size_t n) {
        while (n > 0) {
            const ssize_t w = ::send(fd, p, n, MSG_NOSIGNAL);
            if (w <= 0) return false;
            p += w;
            n -= static_cast<std::size_t>(w);
        }
        return true;
    }

    // Forwards the complete frames in `d`; returns false when the pair was closed.
    bool forward(Direction& d, int to, bool cut_here) {
        while (d.pending.size() >= 8) {
            const std::size_t total = 6u + ((std::size_t{d.pending[4]} << 8) | d.pending[5]);
            if (d.pending.size() < total) break;
            if (d.pending[7] == 0x17) ++d.fc23;
            if (cut_here && d.fc23 == index_ && cuts_ == 0) {
                send_all(to, d.pending.data(), total / 2);
                ++cuts_;
                close_pair();
                return false;
            }
            if (!send_all(to, d.pending.data(), total)) {
                close_pair();
                return false;
            }
            d.pending.erase(d.pending.begin(),
                            d.pending.begin() + static_cast<std::ptrdiff_t>(total));
        }
        return true;
    }

    bool pump(int from, int to, Direction& d, bool cut_here) {
        std::uint8_t buf[1024];
        const ssize_t n = ::recv(from, buf, sizeof buf, 0);
        if (n <= 0) {
            close_pair();
            return false;
        }
        d.pending.insert(d.pending.end(), buf, buf + n);
        return forward(d, to, cut_here);
    }

    void run() {
        while (!runner_.stop) {
            pollfd p[3] = {{listen_, POLLIN, 0}, {client_, POLLIN, 0}, {server_, POLLIN, 0}};
            if (::poll(p, 3, 20) <= 0) continue;
            if ((p[0].revents & POLLIN) != 0) {
                const int c = ::accept4(listen_, nullptr, nullptr, SOCK_CLOEXEC);
                if (c < 0) continue;
                close_pair();  // a reconnecting master replaces the old pair
                const int s = tcp_socket();
                sockaddr_in a = loopback(upstream_);
                if (::connect(s, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
                    ::close(c);
                    ::close(s);
                    continue;
                }
                const int one = 1;
                ::setsockopt(c, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
                ::setsockopt(s, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
                client_ = c;
                server_ = s;
                ++accepted_;
                continue;  // the pair's descriptors were not in this poll
            }
            if ((p[1].revents & (POLLIN | POLLHUP | POLLERR)) != 0 &&
                !pump(client_, server_, requests_, cut_ == Cut::kRequest)) {
                continue;
            }
            if ((p[2].revents & (POLLIN | POLLHUP | POLLERR)) != 0)
                pump(server_, client_, responses_, cut_ == Cut::kResponse);
        }
    }

    std::uint16_t upstream_;
    Cut cut_;
    int index_;
    int listen_ = -1;
    int client_ = -1;
    int server_ = -1;
    std::uint16_t port_ = 0;
    Direction requests_;
    Direction responses_;
    std::atomic<int> cuts_{0};
    std::atomic<int> accepted_{0};
    Runner runner_;
};

// The pathstream_pty_fault_proxy program (sim/modbus), run as a child: its ptys A and B joined
// by a line that corrupts and drops bytes, seeded. (The PtyFaultProxy class itself is not
// linked into host_tests; the program is the same class behind a main.)
class FaultLine {
public:
    FaultLine(double corrupt_rate, double drop_rate, unsigned seed) {
        const std::filesystem::path program =
            std::filesystem::canonical("/proc/self/exe").parent_path().parent_path() / "sim" /
            "modbus" / "pathstream_pty_fault_proxy";
        INFO("build the target pathstream_pty_fault_proxy (" << program.string() << ")");
        REQUIRE(std::filesystem::exists(program));
        int out[2];
        REQUIRE(::pipe2(out, O_CLOEXEC) == 0);
        const std::string corrupt = std::to_string(corrupt_rate), drop = std::to_string(drop_rate),
                          seed_text = std::to_string(seed);
        pid_ = ::fork();
        REQUIRE(pid_ >= 0);
        if (pid_ == 0) {
            ::dup2(out[1], STDOUT_FILENO);
            ::execl(program.c_str(), program.c_str(), "--corrupt-rate", corrupt.c_str(),
                    "--drop-rate", drop.c_str(), "--seed", seed_text.c_str(),
                    static_cast<char*>(nullptr));
            ::_exit(127);
        }
        ::close(out[1]);
        // "A /dev/pts/X\nB /dev/pts/Y\n", within 5 s.
        std::string text;
        const auto deadline = SteadyClock::now() + std::chrono::seconds(5);
        while (std::count(text.begin(), text.end(), '\n') < 2 && SteadyClock::now() < deadline) {
            pollfd p{out[0], POLLIN, 0};
            if (::poll(&p, 1, 100) <= 0) continue;
            char buf[256];
            const ssize_t n = ::read(out[0], buf, sizeof buf);
            if (n <= 0) break;
            text.append(buf, static_cast<std::size_t>(n));
        }
        ::close(out[0]);
        const std::size_t a = text.find("A "), b = text.find("\nB ");
        INFO("proxy printed: " << text);
        REQUIRE(a == 0);
        REQUIRE(b != std::string::npos);
        path_a_ = text.substr(2, b - 2);
        path_b_ = text.substr(b + 3, text.find('\n', b + 1) - b - 3);
    }
    ~FaultLine() {
        if (pid_ > 0) {
            ::kill(pid_, SIGTERM);
            ::waitpid(pid_, nullptr, 0);
        }
    }
    const std::string& path_a() const { return path_a_; }
    const std::string& path_b() const { return path_b_; }

private:
    pid_t pid_ = -1;
    std::string path_a_, path_b_;
};

// Forwards every call to the device that is current: swapping it is a device that restarted
// behind a link that stayed up (a gateway's TCP connection, a serial line). Device thread only.
class SwappableHandler final : public hal::ModbusRegisterHandler {
public:
    linux_device::ModbusMotionDevice* device = nullptr;

    hal::ModbusException read_input_registers(std::uint16_t a, std::uint16_t n,
                                              std::uint16_t* out) override {
        return device->handler().read_input_registers(a, n, out);
    }
    hal::ModbusException read_holding_registers(std::uint16_t a, std::uint16_t n,
                                                std::uint16_t* out) override {
        return device->handler().read_holding_registers(a, n, out);
    }
    hal::ModbusException write_holding_registers(std::uint16_t a, std::uint16_t n,
                                                 const std::uint16_t* v) override {
        return device->handler().write_holding_registers(a, n, v);
    }
    hal::ModbusException write_read_holding_registers(std::uint16_t wa, std::uint16_t wn,
                                                      const std::uint16_t* v, std::uint16_t ra,
                                                      std::uint16_t rn,
                                                      std::uint16_t* out) override {
        return device->handler().write_read_holding_registers(wa, wn, v, ra, rn, out);
    }
};

double seconds_since(SteadyClock::time_point t) {
    return std::chrono::duration<double>(SteadyClock::now() - t).count();
}

}  // namespace

TEST_CASE("a TCP connection cut mid-frame: the host reconnects and no span is lost or run twice",
          "[modbus][faults][threads]") {
    const bool response_lost = GENERATE(true, false);
    const Job job = plan_example("wave.json");
    REQUIRE(job.plan.spans.size() > 40);  // several batches: the cut falls mid-stream
    const auto device = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    device->record(true);
    hal::ModbusServer server = hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0, 4});
    Runner loop;
    run_device(loop, *device, server, 10.0);

    INFO((response_lost ? "third batch's response cut" : "third batch's request cut"));
    TcpCutProxy proxy(server.port(),
                      response_lost ? TcpCutProxy::Cut::kResponse : TcpCutProxy::Cut::kRequest, 3);
    host::StreamOptions o;
    o.target = tcp_target(proxy.port());
    o.response_timeout_ms = 300;
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    loop.join();

    REQUIRE(proxy.cuts() == 1);
    CHECK(proxy.accepted() == 2);  // the first connection and the one after the cut
    CHECK(report.reconnects >= 1);
    CHECK(report.retries >= 1);
    // The batch whose response was lost was applied, then sent again: the device recognised the
    // repeat by its sequence numbers and did not queue it twice. A lost request was never applied.
    CHECK(report.duplicates == (response_lost ? 1u : 0u));
    CHECK(report.spans_sent == job.plan.spans.size());
    check_executed(job, *device, report);
}

TEST_CASE(
    "an RTU line that corrupts and drops ~1 % of bytes: retries, and the drawing completes exactly",
    "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    FaultLine line(0.006, 0.004, 11);
    const auto device = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    device->record(true);
    hal::ModbusServerOptions so;
    so.byte_timeout =
        std::chrono::milliseconds(20);  // a frame cut by a dropped byte is given up soon
    hal::ModbusServer server =
        hal::ModbusServer::rtu(device->handler(), {line.path_a(), 115200, 'N', 8, 1}, so);
    Runner loop;
    run_device(loop, *device, server, 5.0);

    host::StreamOptions o;
    o.target = "modbus-rtu://" + line.path_b() + "?baud=115200&parity=N&unit=1";
    // A pty answers within a millisecond or two: anything later is lost. Under ThreadSanitizer
    // the device runs 5-15x slower, and an answer later than the timeout plus the line's
    // settling time would be read as the next request's (RTU has no transaction id); that
    // build gets a timeout that keeps the test's premise, not a weaker check.
#if defined(__SANITIZE_THREAD__)
    o.response_timeout_ms = 200;
#else
    o.response_timeout_ms = 20;
#endif
    o.attempts = 5;
    o.lead_seconds = 0.5;
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    loop.join();

    INFO("rtu faults: " << report.transactions << " transactions, " << report.retries
                        << " retries, " << report.batches << " batches, " << report.wall_seconds
                        << " s, underruns " << report.underruns << ", bad frames "
                        << server.counters().bad_frames.load() << ", requests "
                        << server.counters().requests.load());
    CHECK(report.retries > 0);
    CHECK(server.counters().bad_frames.load() > 0);
    check_executed(job, *device, report);
}

TEST_CASE(
    "a device power-cycled mid-stream (TCP server gone and back on the same port): the host stops "
    "with "
    "'restarted'",
    "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    std::unique_ptr<linux_device::ModbusMotionDevice> first =
        linux_device::ModbusMotionDevice::create(start_of(job.plan));
    std::unique_ptr<linux_device::ModbusMotionDevice> second;
    std::optional<hal::ModbusServer> server =
        hal::ModbusServer::tcp(first->handler(), {"127.0.0.1", 0, 4});
    const std::uint16_t port = server->port();
    Runner loop;
    loop.thread = std::thread([&] {
        linux_device::DeviceLoopOptions lo;
        lo.time_scale = 10.0;
        std::atomic<bool> restart{false};
        // Phase 1: the first device until it has accepted 20 spans.
        linux_device::run_device_loop(
            *first,
            [&](std::chrono::microseconds w) {
                server->poll_once(w);
                if (status_u32(*first, st::kLastAcceptedSequence) >= 20 || loop.stop)
                    restart = true;
            },
            lo, restart);
        // Power cycle: every connection closes, a fresh device (same start, unconfigured) serves
        // the same port.
        server.reset();
        second = linux_device::ModbusMotionDevice::create(start_of(job.plan));
        server.emplace(hal::ModbusServer::tcp(second->handler(), {"127.0.0.1", port, 4}));
        linux_device::run_device_loop(
            *second, [&](std::chrono::microseconds w) { server->poll_once(w); }, lo, loop.stop);
    });
    host::StreamOptions o;
    o.target = tcp_target(port);
    o.response_timeout_ms = 300;
    o.link_timeout_seconds = 3;
    const auto t0 = SteadyClock::now();
    REQUIRE_THROWS_MATCHES(host::stream_modbus(job.plan, job.machine, o), host::StreamError,
                           Catch::Matchers::Predicate<host::StreamError>(
                               [](const host::StreamError& e) {
                                   return std::string(e.what()).find("restarted") !=
                                          std::string::npos;
                               },
                               "message says the device restarted"));
    CHECK(seconds_since(t0) < 10);
    loop.join();
    REQUIRE(second != nullptr);
    // Nothing continued blind: the fresh device was never configured, fed or started.
    CHECK(status_u32(*second, st::kLastAcceptedSequence) == 0);
    CHECK(status_u16(*second, st::kState) == 0);
    CHECK((status_u16(*second, st::kFlags) & 1u) == 0);
}

TEST_CASE("a device restarted behind a link that stays up (RTU): the host stops with 'restarted'",
          "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    const auto first = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    const auto second = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    SwappableHandler handler;
    handler.device = first.get();
    hal::ModbusServer server = hal::ModbusServer::rtu_pty(handler);
    Runner loop;
    loop.thread = std::thread([&] {
        linux_device::DeviceLoopOptions lo;
        lo.time_scale = 10.0;
        std::atomic<bool> restart{false};
        linux_device::run_device_loop(
            *first,
            [&](std::chrono::microseconds w) {
                server.poll_once(w);
                if (status_u32(*first, st::kLastAcceptedSequence) >= 20 || loop.stop)
                    restart = true;
            },
            lo, restart);
        handler.device = second.get();
        linux_device::run_device_loop(
            *second, [&](std::chrono::microseconds w) { server.poll_once(w); }, lo, loop.stop);
    });
    host::StreamOptions o;
    o.target = "modbus-rtu://" + server.client_device() + "?baud=115200&parity=N&unit=1";
    o.response_timeout_ms = 200;
    o.link_timeout_seconds = 3;
    try {
        host::stream_modbus(job.plan, job.machine, o);
        FAIL("the stream completed on a restarted device");
    } catch (const host::StreamError& e) {
        CHECK_THAT(e.what(), Contains("restarted"));
    }
    loop.join();
    CHECK(status_u32(*second, st::kLastAcceptedSequence) == 0);
    CHECK(status_u16(*second, st::kState) == 0);
    CHECK((status_u16(*second, st::kFlags) & 1u) == 0);
}

TEST_CASE(
    "the queue runs dry: the device stops within its limits, reports the underrun, resumes, and "
    "the path is "
    "exact",
    "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    const auto device = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    device->record(true);
    device->record_every_tick(true);
    hal::ModbusServer server = hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0, 4});
    // Seen by the device thread in its own status block: holding, with the underrun flag.
    bool saw_underrun_hold = false;
    Runner loop;
    loop.thread = std::thread([&] {
        linux_device::DeviceLoopOptions lo;
        lo.time_scale = 10.0;
        linux_device::run_device_loop(
            *device,
            [&](std::chrono::microseconds w) {
                server.poll_once(w);
                if (status_u16(*device, st::kState) ==
                        static_cast<std::uint16_t>(device::DeviceState::kHolding) &&
                    (status_u16(*device, st::kFlags) & 2u) != 0) {
                    saw_underrun_hold = true;
                }
            },
            lo, loop.stop);
    });
    // A host too slow for the device: one tick of lead wanted, and 40 ms (400 device ticks at
    // 10x) between polls, so each batch runs out before the next one arrives.
    host::StreamOptions o;
    o.target = tcp_target(server.port());
    o.lead_seconds = 0.001;
    o.poll_interval_ms = 40;
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    loop.join();

    CHECK(saw_underrun_hold);
    CHECK(report.underruns >= 2);
    check_executed(job, *device, report);

    // Every tick the axes were commanded (path, stop, rest and re-entry alike) within the
    // limits: first and second differences of the setpoints, with the rounding allowance of
    // the integer setpoints (+-1/2 LSB each: 1 LSB on a difference, 2 on a second difference).
    const std::vector<Lsb>& all = device->every_tick_setpoints();
    const std::size_t axes = 2;
    REQUIRE(all.size() / axes > job.plan.total_ticks);  // the stops and re-entries are in it
    const double hz = job.machine.tick_hz;
    for (std::size_t a = 0; a < axes; ++a) {
        const double v_max = job.machine.axes[a].max_velocity / job.machine.mm_per_lsb / hz + 1.0;
        const double a_max =
            job.machine.axes[a].max_acceleration / job.machine.mm_per_lsb / (hz * hz) + 2.0;
        for (std::size_t k = 1; k + 1 < all.size() / axes; ++k) {
            const double x0 = all[(k - 1) * axes + a], x1 = all[k * axes + a],
                         x2 = all[(k + 1) * axes + a];
            INFO("tick " << k << " axis " << a << ": " << x0 << ' ' << x1 << ' ' << x2);
            REQUIRE(std::abs(x2 - x1) <= v_max);
            REQUIRE(std::abs(x2 - 2 * x1 + x0) <= a_max);
        }
    }
}

TEST_CASE("a lead longer than the device's queue holds: the host starts when the queue is full",
          "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    const auto device = linux_device::ModbusMotionDevice::create(start_of(job.plan));
    device->record(true);
    hal::ModbusServer server = hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0, 4});
    Runner loop;
    run_device(loop, *device, server, 10.0);
    host::StreamOptions o;
    o.target = tcp_target(server.port());
    o.lead_seconds = 60;  // far more than 64 spans of 8 ticks
    o.link_timeout_seconds = 2;
    const auto t0 = SteadyClock::now();
    const host::StreamReport report = host::stream_modbus(job.plan, job.machine, o);
    loop.join();
    CHECK(seconds_since(t0) < 10);
    check_executed(job, *device, report);
}

TEST_CASE("a dead TCP peer (accepts, never answers): StreamError within the link timeout",
          "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    SilentListener silent;
    host::StreamOptions o;
    o.target = tcp_target(silent.port);
    o.response_timeout_ms = 50;
    o.attempts = 2;
    o.link_timeout_seconds = 0.4;
    const auto t0 = SteadyClock::now();
    try {
        host::stream_modbus(job.plan, job.machine, o);
        FAIL("streamed to a peer that never answers");
    } catch (const host::StreamError& e) {
        CHECK_THAT(e.what(), Contains(o.target) && Contains("no answer"));
    }
    CHECK(seconds_since(t0) < 10 * o.link_timeout_seconds);
}

TEST_CASE("nothing listening on the TCP port: StreamError at once, not a transport exception",
          "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    std::uint16_t port = 0;
    {
        SilentListener closed_soon;  // an ephemeral port that was free a moment ago
        port = closed_soon.port;
    }
    host::StreamOptions o;
    o.target = tcp_target(port);
    o.response_timeout_ms = 50;
    o.attempts = 2;
    // A refusal is an answer: no retry until the link timeout (which would end with another
    // message, the transport's error in brackets).
    o.link_timeout_seconds = 60;
    try {
        host::stream_modbus(job.plan, job.machine, o);
        FAIL("streamed to a closed port");
    } catch (const host::StreamError& e) {
        CHECK_THAT(e.what(),
                   Contains(o.target) && Contains("nothing listens there (connection refused)"));
    }
}

TEST_CASE("a dead RTU peer (a pty nobody serves): StreamError within the link timeout",
          "[modbus][faults][threads]") {
    const Job job = plan_example("wave.json");
    hal::PseudoTerminal unserved(true);
    host::StreamOptions o;
    o.target = "modbus-rtu://" + unserved.peer_path() + "?baud=115200&parity=N&unit=1";
    o.response_timeout_ms = 50;
    o.attempts = 2;
    o.link_timeout_seconds = 0.4;
    const auto t0 = SteadyClock::now();
    try {
        host::stream_modbus(job.plan, job.machine, o);
        FAIL("streamed to a pty nobody serves");
    } catch (const host::StreamError& e) {
        CHECK_THAT(e.what(), Contains(o.target) && Contains("no answer"));
    }
    CHECK(seconds_since(t0) < 10 * o.link_timeout_seconds);
}
