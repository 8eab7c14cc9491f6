#include "pathstream/hal/modbus_server.hpp"

#include <fcntl.h>
#include <modbus/modbus.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <optional>
#include <system_error>
#include <thread>
#include <vector>

#include "mbap_assembler.hpp"
#include "modbus_dispatch.hpp"
#include "pathstream/hal/pseudo_terminal.hpp"

namespace pathstream::hal {
namespace {

using Clock = std::chrono::steady_clock;

[[noreturn]] void throw_errno(const std::string& what, int err = errno) {
    throw std::system_error(err, std::generic_category(), what);
}

void bump(std::atomic<std::uint64_t>& counter, std::uint64_t by = 1) {
    counter.fetch_add(by, std::memory_order_release);
}

// Bound, listening, non-blocking TCP socket for host:port (port 0 = ephemeral).
int listen_on(const ModbusTcpEndpoint& endpoint) {
    addrinfo hints{};
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
    addrinfo* found = nullptr;
    const std::string service = std::to_string(endpoint.port);
    const int gai = getaddrinfo(endpoint.host.c_str(), service.c_str(), &hints, &found);
    if (gai != 0) {
        throw std::system_error(
            EINVAL, std::generic_category(),
            "Modbus TCP server: cannot resolve '" + endpoint.host + "': " + gai_strerror(gai));
    }
    int err = 0;
    for (addrinfo* a = found; a != nullptr; a = a->ai_next) {
        const int fd =
            ::socket(a->ai_family, a->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, a->ai_protocol);
        if (fd < 0) {
            err = errno;
            continue;
        }
        const int on = 1;
        // A restarted server must be able to rebind while old connections sit in TIME_WAIT.
        setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on);
        if (::bind(fd, a->ai_addr, a->ai_addrlen) == 0 && ::listen(fd, 8) == 0) {
            freeaddrinfo(found);
            return fd;
        }
        err = errno;
        ::close(fd);
    }
    freeaddrinfo(found);
    throw_errno("Modbus TCP server: cannot listen on " + endpoint.host + ":" + service, err);
}

std::uint16_t bound_port(int fd) {
    sockaddr_storage addr{};
    socklen_t len = sizeof addr;
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len) != 0) throw_errno("getsockname");
    if (addr.ss_family == AF_INET6) return ntohs(reinterpret_cast<sockaddr_in6*>(&addr)->sin6_port);
    return ntohs(reinterpret_cast<sockaddr_in*>(&addr)->sin_port);
}

// poll(2) with a microsecond timeout: a 1 kHz device waits 0.6 ms, not 0 ms (a busy loop).
int poll_for(pollfd* fds, std::size_t count, std::chrono::microseconds wait) {
    const auto us = std::max<std::int64_t>(0, wait.count());
    const timespec t{static_cast<time_t>(us / 1'000'000), static_cast<long>(us % 1'000'000) * 1000};
    return ::ppoll(fds, count, &t, nullptr);
}

void set_timeouts(modbus_t* ctx, std::chrono::milliseconds byte_timeout) {
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(byte_timeout).count();
    const auto sec = static_cast<std::uint32_t>(us / 1'000'000);
    const auto usec = static_cast<std::uint32_t>(us % 1'000'000);
    modbus_set_byte_timeout(ctx, sec, usec);
    // poll() has already seen the first byte; this bounds modbus_receive should it not come
    // (0/0 would mean "wait forever").
    modbus_set_indication_timeout(ctx, sec, usec == 0 && sec == 0 ? 1000 : usec);
}

}  // namespace

struct ModbusServer::Impl {
    struct Client {
        int fd;
        Clock::time_point last_active;  ///< the last request answered (at first: accepted)
        Clock::time_point last_byte;    ///< of the frame in progress
        std::uint64_t requests = 0;     ///< answered on this connection
        detail::MbapAssembler frame;
    };

    Impl(ModbusRegisterHandler& h, ModbusFraming f, const ModbusServerOptions& o)
        : handler(h), framing(f), options(o) {}

    ~Impl() {
        for (const Client& c : clients) ::close(c.fd);
        if (listen_fd >= 0) ::close(listen_fd);
        if (ctx != nullptr) {
            // A serial port opened by libmodbus gets its termios restored and is closed; a
            // pty's near end belongs to PseudoTerminal, TCP sockets were closed above.
            if (serial_opened) modbus_close(ctx);
            modbus_free(ctx);
        }
    }

    ModbusRegisterHandler& handler;
    ModbusFraming framing;
    ModbusServerOptions options;
    modbus_t* ctx = nullptr;
    bool serial_opened = false;  // modbus_connect succeeded on a serial device
    int serial_fd = -1;
    std::optional<PseudoTerminal> pty;
    std::string device;
    int listen_fd = -1;
    std::uint16_t port = 0;
    std::size_t max_clients = 1;
    std::vector<Client> clients;
    ModbusServerCounters counters;
    detail::DispatchScratch scratch;
    std::uint8_t frame[MODBUS_TCP_MAX_ADU_LENGTH] = {};

    std::size_t poll_tcp(std::chrono::microseconds max_wait);
    std::size_t poll_rtu(std::chrono::microseconds max_wait);
    void accept_clients();
    void close_client(std::size_t index);
    std::size_t evictee() const;
    bool read_tcp(Client& client, std::size_t& handled);  // false: close the connection
    bool serve_one_tcp(Client& client);                   // false: close the connection
    std::size_t serve_one_rtu();
    void count(const detail::DispatchOutcome& outcome);
};

void ModbusServer::Impl::close_client(std::size_t index) {
    ::close(clients[index].fd);
    clients.erase(clients.begin() + static_cast<std::ptrdiff_t>(index));
    bump(counters.connections_closed);
}

void ModbusServer::Impl::accept_clients() {
    for (;;) {
        const int fd = ::accept4(listen_fd, nullptr, nullptr, SOCK_CLOEXEC | SOCK_NONBLOCK);
        if (fd < 0) return;  // EAGAIN: none pending; other errors: that peer already left
        const int on = 1;
        // Requests and responses are single small segments: Nagle + delayed ACK would add
        // tens of milliseconds to every transaction.
        setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &on, sizeof on);
        if (clients.size() >= max_clients) close_client(evictee());
        const Clock::time_point now = Clock::now();
        clients.push_back({fd, now, now, 0, {}});
        bump(counters.connections_accepted);
    }
}

std::size_t ModbusServer::Impl::evictee() const {
    // Full: a connection that never completed a request (a scan, a flood, a dribbler) goes
    // first, so a master that is streaming keeps its slot; among equals the longest idle, most
    // likely a master that vanished without a FIN and is the newcomer coming back.
    const auto victim =
        std::min_element(clients.begin(), clients.end(), [](const Client& a, const Client& b) {
            if ((a.requests == 0) != (b.requests == 0)) return a.requests == 0;
            return a.last_active < b.last_active;
        });
    return static_cast<std::size_t>(victim - clients.begin());
}

void ModbusServer::Impl::count(const detail::DispatchOutcome& outcome) {
    bump(counters.requests);
    if (outcome.exception) bump(counters.exceptions);
    if (outcome.broadcast) bump(counters.broadcasts);
    if (outcome.sent > 0) bump(counters.adu_bytes_sent, static_cast<std::uint64_t>(outcome.sent));
}

// Reads what the socket holds, up to the end of the frame in progress, without waiting;
// answers the frame once whole. At most one request per call.
bool ModbusServer::Impl::read_tcp(Client& client, std::size_t& handled) {
    for (;;) {
        const ssize_t n =
            ::recv(client.fd, client.frame.write_pointer(), client.frame.wanted(), MSG_DONTWAIT);
        if (n == 0) return false;  // the peer closed
        if (n < 0) return errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR;
        client.last_byte = Clock::now();
        switch (client.frame.added(static_cast<std::size_t>(n))) {
            case detail::MbapAssembler::State::kPartial:
                continue;
            case detail::MbapAssembler::State::kBad:
                // Out of step for good (not MBAP, or a length no request has): the master
                // reconnects.
                bump(counters.bad_frames);
                return false;
            case detail::MbapAssembler::State::kComplete: {
                const bool keep = serve_one_tcp(client);
                client.frame.clear();
                ++handled;
                return keep;
            }
        }
    }
}

bool ModbusServer::Impl::serve_one_tcp(Client& client) {
    const int length = static_cast<int>(client.frame.size());
    client.last_active = Clock::now();
    ++client.requests;
    bump(counters.adu_bytes_received, static_cast<std::uint64_t>(length));
    // libmodbus only frames the reply here: it gets the whole request we assembled.
    std::copy(client.frame.frame(), client.frame.frame() + length, frame);
    modbus_set_socket(ctx, client.fd);
    const detail::DispatchOutcome outcome =
        detail::dispatch_modbus_request(ctx, framing, frame, length, handler, scratch);
    count(outcome);
    // A failed send (the peer's window full: it is not reading its replies) closes it; the
    // socket is non-blocking, so such a peer never holds the server.
    return outcome.sent >= 0;
}

std::size_t ModbusServer::Impl::poll_tcp(std::chrono::microseconds max_wait) {
    std::vector<pollfd> fds;
    fds.reserve(clients.size() + 1);
    fds.push_back({listen_fd, POLLIN, 0});
    const Clock::time_point start = Clock::now();
    Clock::time_point wake = start + max_wait;
    for (const Client& c : clients) {
        fds.push_back({c.fd, POLLIN, 0});
        // A frame in progress must not outlive its byte timeout even on a quiet server.
        if (!c.frame.empty()) wake = std::min(wake, c.last_byte + options.byte_timeout);
    }
    const int ready = poll_for(fds.data(), fds.size(),
                               std::chrono::ceil<std::chrono::microseconds>(wake - start));

    std::size_t handled = 0;
    // Serve existing connections first (indices stay valid: accepting appends at the end).
    std::vector<int> to_close;
    const Clock::time_point now = Clock::now();
    for (std::size_t i = 1; i < fds.size(); ++i) {
        Client& client = clients[i - 1];
        if (ready > 0 && fds[i].revents != 0 && !read_tcp(client, handled)) {
            to_close.push_back(client.fd);
        } else if (!client.frame.empty() && now - client.last_byte > options.byte_timeout) {
            bump(counters.bad_frames);  // a frame stalled mid-way: the master resends it
            to_close.push_back(client.fd);
        }
    }
    for (const int fd : to_close) {
        const auto it = std::find_if(clients.begin(), clients.end(),
                                     [fd](const Client& c) { return c.fd == fd; });
        if (it != clients.end()) close_client(static_cast<std::size_t>(it - clients.begin()));
    }
    if (ready > 0 && fds[0].revents != 0) accept_clients();
    return handled;
}

std::size_t ModbusServer::Impl::serve_one_rtu() {
    const int length = modbus_receive(ctx, frame);
    if (length == 0) {  // libmodbus read a whole frame for another unit id and dropped it
        bump(counters.ignored);
        return 0;
    }
    if (length < 0) {
        // CRC error, incomplete frame (byte timeout) or garbage: discard what is buffered so
        // the master's retry starts on a clean line.
        bump(counters.bad_frames);
        modbus_flush(ctx);
        return 0;
    }
    bump(counters.adu_bytes_received, static_cast<std::uint64_t>(length));
    count(detail::dispatch_modbus_request(ctx, framing, frame, length, handler, scratch));
    return 1;
}

std::size_t ModbusServer::Impl::poll_rtu(std::chrono::microseconds max_wait) {
    pollfd fd{serial_fd, POLLIN, 0};
    const int ready = poll_for(&fd, 1, max_wait);
    if (ready <= 0) return 0;
    if ((fd.revents & POLLIN) == 0) {
        // Hang-up or error without data (a USB adapter unplugged): nothing to read, and
        // poll would return at once forever. Wait out the slot instead of spinning.
        std::this_thread::sleep_for(max_wait);
        return 0;
    }
    return serve_one_rtu();
}

ModbusServer::ModbusServer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ModbusServer::ModbusServer(ModbusServer&&) noexcept = default;
ModbusServer& ModbusServer::operator=(ModbusServer&&) noexcept = default;
ModbusServer::~ModbusServer() = default;

ModbusServer ModbusServer::tcp(ModbusRegisterHandler& handler, const ModbusTcpEndpoint& endpoint,
                               const ModbusServerOptions& options) {
    auto impl = std::make_unique<Impl>(handler, ModbusFraming::kTcp, options);
    impl->listen_fd = listen_on(endpoint);
    impl->port = bound_port(impl->listen_fd);
    impl->max_clients = std::max<std::size_t>(1, endpoint.max_clients);
    // The context is only a framing engine here: we accept ourselves and lend it each
    // connection's socket (modbus_set_socket) before receiving or replying.
    impl->ctx = modbus_new_tcp("127.0.0.1", impl->port);
    if (impl->ctx == nullptr) throw_errno("modbus_new_tcp");
    set_timeouts(impl->ctx, options.byte_timeout);
    return ModbusServer(std::move(impl));
}

namespace {

void check_unit(int unit) {
    if (unit < 1 || unit > 247) {
        throw std::system_error(
            EINVAL, std::generic_category(),
            "Modbus RTU server: unit id " + std::to_string(unit) + " is not in 1..247");
    }
}

}  // namespace

ModbusServer ModbusServer::rtu(ModbusRegisterHandler& handler, const ModbusSerialLine& line,
                               const ModbusServerOptions& options) {
    check_unit(options.unit);
    auto impl = std::make_unique<Impl>(handler, ModbusFraming::kRtu, options);
    impl->device = line.device;
    impl->ctx =
        modbus_new_rtu(line.device.c_str(), line.baud, line.parity, line.data_bits, line.stop_bits);
    if (impl->ctx == nullptr)
        throw_errno("Modbus RTU server: bad serial settings for " + line.device);
    modbus_set_slave(impl->ctx, options.unit);
    set_timeouts(impl->ctx, options.byte_timeout);
    if (modbus_connect(impl->ctx) != 0)
        throw_errno("Modbus RTU server: cannot open " + line.device);
    impl->serial_opened = true;
    impl->serial_fd = modbus_get_socket(impl->ctx);
    return ModbusServer(std::move(impl));
}

ModbusServer ModbusServer::rtu_pty(ModbusRegisterHandler& handler,
                                   const ModbusServerOptions& options) {
    check_unit(options.unit);
    auto impl = std::make_unique<Impl>(handler, ModbusFraming::kRtu, options);
    impl->pty.emplace();
    impl->device = impl->pty->peer_path();
    // An RTU context that is never modbus_connect()ed: we lend it the pty's near end. The
    // device name only labels the context; baud and format are meaningless on a pty.
    impl->ctx = modbus_new_rtu(impl->device.c_str(), 115200, 'N', 8, 1);
    if (impl->ctx == nullptr) throw_errno("modbus_new_rtu");
    modbus_set_slave(impl->ctx, options.unit);
    set_timeouts(impl->ctx, options.byte_timeout);
    impl->serial_fd = impl->pty->fd();
    modbus_set_socket(impl->ctx, impl->serial_fd);
    return ModbusServer(std::move(impl));
}

std::size_t ModbusServer::poll_once(std::chrono::microseconds max_wait) {
    if (max_wait.count() < 0) max_wait = std::chrono::microseconds(0);
    return impl_->framing == ModbusFraming::kTcp ? impl_->poll_tcp(max_wait)
                                                 : impl_->poll_rtu(max_wait);
}

std::size_t ModbusServer::serve_for(std::chrono::milliseconds duration) {
    const Clock::time_point end = Clock::now() + duration;
    std::size_t handled = 0;
    for (;;) {
        const auto left = std::chrono::ceil<std::chrono::microseconds>(end - Clock::now());
        if (left.count() <= 0) return handled;
        handled += poll_once(left);
    }
}

std::uint16_t ModbusServer::port() const {
    return impl_->port;
}
const std::string& ModbusServer::client_device() const {
    return impl_->device;
}
const ModbusServerCounters& ModbusServer::counters() const {
    return impl_->counters;
}
std::size_t ModbusServer::open_connections() const {
    // From the counters, not the client list: another thread may be serving (and editing the
    // list). Closed is read first, so the difference is never negative.
    const std::uint64_t closed = impl_->counters.connections_closed.load(std::memory_order_acquire);
    const std::uint64_t accepted =
        impl_->counters.connections_accepted.load(std::memory_order_acquire);
    return static_cast<std::size_t>(accepted - closed);
}

}  // namespace pathstream::hal
