// The HTTP transport of `pathstream serve` against hostile clients on loopback sockets: slow
// and endless request heads, silent event listeners, oversized and chunked bodies, a client
// that leaves while its request is worked on, and a stop that must get through all of them.
// No assertion is on wall time: each waits for an outcome (with a generous bound that only a
// hang reaches) and checks counts.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "serve/event_hub.hpp"
#include "serve/http_server.hpp"

using namespace pathstream::host::serve;
using namespace std::chrono_literals;

namespace {

/// A server on a free loopback port, run on its own thread for the test's life.
struct RunningServer {
    EventHub hub;
    HttpServer server;
    unsigned port = 0;
    std::thread thread;

    explicit RunningServer(HttpLimits limits, const std::function<void(HttpServer&)>& routes)
        : server(limits, hub) {
        routes(server);
        server.events("/events");
        port = server.bind("127.0.0.1", 0);
        thread = std::thread([this] { server.run(); });
    }
    ~RunningServer() {
        hub.close();
        server.stop();
        thread.join();
    }
};

/// A blocking client socket.
struct Client {
    int fd = -1;
    explicit Client(unsigned port, int receive_buffer = 0) {
        fd = ::socket(AF_INET, SOCK_STREAM, 0);
        if (receive_buffer > 0)
            ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
        sockaddr_in a{};
        a.sin_family = AF_INET;
        a.sin_port = htons(static_cast<std::uint16_t>(port));
        a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        REQUIRE(::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0);
    }
    ~Client() { ::close(fd); }
    bool send(const std::string& text) const {
        return ::send(fd, text.data(), text.size(), MSG_NOSIGNAL) ==
               static_cast<ssize_t>(text.size());
    }
    /// Everything until the server closes or `limit` passes.
    std::string read_all(std::chrono::milliseconds limit = 30s) const {
        std::string out;
        const auto end = std::chrono::steady_clock::now() + limit;
        while (std::chrono::steady_clock::now() < end) {
            pollfd p{fd, POLLIN, 0};
            if (::poll(&p, 1, 50) <= 0) continue;
            char buffer[4096];
            const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
            if (n <= 0) break;
            out.append(buffer, static_cast<std::size_t>(n));
        }
        return out;
    }
    /// The first response's status line (reads until a blank line).
    std::string status_line(std::chrono::milliseconds limit = 30s) const {
        std::string out;
        const auto end = std::chrono::steady_clock::now() + limit;
        while (out.find("\r\n\r\n") == std::string::npos &&
               std::chrono::steady_clock::now() < end) {
            pollfd p{fd, POLLIN, 0};
            if (::poll(&p, 1, 50) <= 0) continue;
            char c;
            if (::recv(fd, &c, 1, 0) != 1) break;
            out += c;
        }
        return out.substr(0, out.find("\r\n"));
    }
    /// True once the server has closed the connection (reads and drops what it sent first).
    bool closed_by_server(std::chrono::milliseconds limit = 30s) const {
        const auto end = std::chrono::steady_clock::now() + limit;
        while (std::chrono::steady_clock::now() < end) {
            pollfd p{fd, POLLIN, 0};
            if (::poll(&p, 1, 50) <= 0) continue;
            char buffer[4096];
            if (::recv(fd, buffer, sizeof buffer, 0) <= 0) return true;
        }
        return false;
    }
};

std::string post(const std::string& path, const std::string& body) {
    return "POST " + path +
           " HTTP/1.1\r\nHost: x\r\nContent-Length: " + std::to_string(body.size()) + "\r\n\r\n" +
           body;
}

HttpResponse ok(const std::string& body) {
    return {200, "text/plain", body, {}};
}

}  // namespace

TEST_CASE("http: a stop answers while every other kind of client holds the server",
          "[serve][http][threads]") {
    HttpLimits limits;
    std::atomic<int> planning{0};
    RunningServer s(limits, [&](HttpServer& h) {
        h.route("POST", "/stop", Lane::stop,
                [](const HttpRequest&, const CancelToken&) { return ok("stopped"); });
        // Work that lasts until it is cancelled: both workers of its lane are taken.
        h.route("POST", "/plan", Lane::work, [&](const HttpRequest&, const CancelToken& cancel) {
            ++planning;
            while (!cancel.cancelled()) std::this_thread::sleep_for(5ms);
            return ok("cancelled");
        });
    });
    std::vector<std::unique_ptr<Client>> others;
    for (int i = 0; i < 64; ++i) {  // event listeners that never read
        others.push_back(std::make_unique<Client>(s.port, 1024));
        REQUIRE(others.back()->send("GET /events HTTP/1.1\r\nHost: x\r\n\r\n"));
    }
    for (int i = 0; i < 64; ++i) {  // request heads that never end
        others.push_back(std::make_unique<Client>(s.port));
        REQUIRE(others.back()->send("GET /stop HTTP/1.1\r\nHost: x\r\nX-Slow: "));
    }
    for (int i = 0; i < 4; ++i) {  // long plans, more than the work lane has workers
        others.push_back(std::make_unique<Client>(s.port));
        REQUIRE(others.back()->send(post("/plan", "{}")));
    }
    for (int i = 0; i < 200 && planning.load() < 2; ++i) std::this_thread::sleep_for(10ms);
    for (int i = 0; i < 100; ++i)
        s.hub.publish("{\"event\":\"device\",\"pad\":\"" + std::string(900, 'x') + "\"}");
    const Client stop(s.port);
    REQUIRE(stop.send(post("/stop", "{}")));
    const std::string answer = stop.read_all(3s);
    CHECK(answer.rfind("HTTP/1.1 200", 0) == 0);
    CHECK(answer.find("stopped") != std::string::npos);
    CHECK(planning.load() == 2);  // the other two plans wait in the work lane's queue
}

TEST_CASE("http: a head that does not end within the deadline is closed",
          "[serve][http][threads]") {
    HttpLimits limits;
    limits.header_deadline = 300ms;
    RunningServer s(limits, [](HttpServer& h) {
        h.route("GET", "/state", Lane::command,
                [](const HttpRequest&, const CancelToken&) { return ok("state"); });
    });
    const Client slow(s.port);
    REQUIRE(slow.send("GET /state HTTP/1.1\r\n"));
    // One byte at a time never resets the deadline: it is the whole head's.
    bool closed = false;
    for (int i = 0; i < 300 && !closed; ++i) {
        closed = !slow.send("X");
        if (!closed) {
            pollfd p{slow.fd, POLLIN, 0};
            closed = ::poll(&p, 1, 100) > 0 && slow.closed_by_server(10ms);
        }
    }
    CHECK(closed);
    const Client fast(s.port);
    REQUIRE(fast.send("GET /state HTTP/1.1\r\nHost: x\r\n\r\n"));
    CHECK(fast.status_line() == "HTTP/1.1 200 OK");
}

TEST_CASE("http: heads too large or with too many fields get 431 before any handler",
          "[serve][http][threads]") {
    HttpLimits limits;
    std::atomic<int> handled{0};
    RunningServer s(limits, [&](HttpServer& h) {
        h.route("GET", "/state", Lane::command, [&](const HttpRequest&, const CancelToken&) {
            ++handled;
            return ok("state");
        });
    });
    {
        const Client c(s.port);
        std::string head = "GET /state HTTP/1.1\r\nHost: x\r\n";
        for (int i = 0; i < 2000; ++i)
            head += "X-Pad-" + std::to_string(i) + ": " + std::string(100, 'a') + "\r\n";
        c.send(head + "\r\n");  // the server may close before it is all sent
        CHECK(c.status_line() == "HTTP/1.1 431 Request Header Fields Too Large");
    }
    {
        const Client c(s.port);
        std::string head = "GET /state HTTP/1.1\r\nHost: x\r\n";
        for (std::size_t i = 0; i < limits.header_fields; ++i)
            head += "A" + std::to_string(i) + ": b\r\n";
        REQUIRE(c.send(head + "\r\n"));
        CHECK(c.status_line() == "HTTP/1.1 431 Request Header Fields Too Large");
    }
    CHECK(handled.load() == 0);
}

TEST_CASE("http: a body past the limit is refused as it arrives, chunked or not",
          "[serve][http][threads]") {
    HttpLimits limits;
    limits.body_bytes = 64 * 1024;
    std::atomic<int> handled{0};
    RunningServer s(limits, [&](HttpServer& h) {
        h.route("POST", "/drawing", Lane::work, [&](const HttpRequest& r, const CancelToken&) {
            ++handled;
            return ok(std::to_string(r.body.size()));
        });
    });
    {
        const Client c(s.port);
        REQUIRE(c.send("POST /drawing HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000\r\n\r\n"));
        CHECK(c.status_line() == "HTTP/1.1 413 Payload Too Large");
    }
    {
        const Client c(s.port);
        REQUIRE(c.send("POST /drawing HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n\r\n"));
        const std::string chunk = "1000\r\n" + std::string(0x1000, '1') + "\r\n";
        for (int i = 0; i < 64 && c.send(chunk); ++i) {
        }
        CHECK(c.status_line() == "HTTP/1.1 413 Payload Too Large");
    }
    {
        const Client c(s.port);  // within the limit, chunked: read whole
        REQUIRE(
            c.send("POST /drawing HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: "
                   "chunked\r\n\r\n4\r\nabcd\r\n0\r\n\r\n"));
        CHECK(c.status_line() == "HTTP/1.1 200 OK");
    }
    CHECK(handled.load() == 1);
}

TEST_CASE("http: a client that leaves cancels the work it asked for", "[serve][http][threads]") {
    HttpLimits limits;
    std::atomic<int> started{0}, cancelled{0};
    RunningServer s(limits, [&](HttpServer& h) {
        h.route("POST", "/plan", Lane::work, [&](const HttpRequest&, const CancelToken& cancel) {
            ++started;
            for (int i = 0; i < 6000 && !cancel.cancelled(); ++i) std::this_thread::sleep_for(5ms);
            if (cancel.cancelled()) ++cancelled;
            return ok("done");
        });
    });
    {
        const Client c(s.port);
        REQUIRE(c.send(post("/plan", "{}")));
        for (int i = 0; i < 500 && started.load() == 0; ++i) std::this_thread::sleep_for(10ms);
    }
    for (int i = 0; i < 3000 && cancelled.load() == 0; ++i) std::this_thread::sleep_for(10ms);
    CHECK(started.load() == 1);
    CHECK(cancelled.load() == 1);
}

TEST_CASE("http: an event listener that does not read is dropped, one that reads is not",
          "[serve][http][threads]") {
    HttpLimits limits;
    limits.event_backlog_bytes = 1u << 20;
    limits.write_deadline = 500ms;
    RunningServer s(limits, [](HttpServer&) {});
    const Client silent(s.port, 1024);
    REQUIRE(silent.send("GET /events HTTP/1.1\r\nHost: x\r\n\r\n"));
    const Client reader(s.port);
    REQUIRE(reader.send("GET /events HTTP/1.1\r\nHost: x\r\n\r\n"));
    std::atomic<bool> reading{true};
    std::atomic<std::size_t> read_bytes{0};
    std::thread drain([&] {
        char buffer[65536];
        while (reading.load()) {
            pollfd p{reader.fd, POLLIN, 0};
            if (::poll(&p, 1, 20) <= 0) continue;
            const ssize_t n = ::recv(reader.fd, buffer, sizeof buffer, 0);
            if (n <= 0) break;
            read_bytes += static_cast<std::size_t>(n);
        }
    });
    for (int i = 0; i < 400 && s.server.connections() < 2; ++i) std::this_thread::sleep_for(5ms);
    REQUIRE(s.server.connections() == 2);
    // Far more than the kernel's buffers hold, at a pace the reader keeps up with (about 10 MB/s).
    const std::string event = "{\"event\":\"progress\",\"pad\":\"" + std::string(4000, 'x') + "\"}";
    for (int i = 0; i < 20000 && s.server.connections() == 2; ++i) {
        s.hub.publish(event);
        if (i % 50 == 49) std::this_thread::sleep_for(20ms);
    }
    for (int i = 0; i < 1000 && s.server.connections() == 2; ++i) std::this_thread::sleep_for(10ms);
    CHECK(s.server.connections() == 1);
    CHECK(silent.closed_by_server(5s));
    const std::size_t before = read_bytes.load();
    s.hub.publish("{\"event\":\"after\"}");
    for (int i = 0; i < 500 && read_bytes.load() == before; ++i) std::this_thread::sleep_for(10ms);
    CHECK(read_bytes.load() > before);
    reading.store(false);
    drain.join();
}

TEST_CASE("http: at the connection cap an idle connection makes room for a request",
          "[serve][http][threads]") {
    HttpLimits limits;
    limits.connections = 16;
    limits.connections_per_client = 8;
    RunningServer s(limits, [](HttpServer& h) {
        h.route("POST", "/stop", Lane::stop,
                [](const HttpRequest&, const CancelToken&) { return ok("stopped"); });
    });
    std::vector<std::unique_ptr<Client>> idle;
    for (int i = 0; i < 40; ++i) idle.push_back(std::make_unique<Client>(s.port));
    const Client stop(s.port);
    REQUIRE(stop.send(post("/stop", "{}")));
    CHECK(stop.status_line() == "HTTP/1.1 200 OK");
    CHECK(s.server.connections() <= limits.connections_per_client);
}

TEST_CASE("http: query strings and cookies", "[serve][http]") {
    const auto q = parse_query("name=a%20b.svg&options=%7B%7D&x&name=second&bad=%zz+1");
    CHECK(q.at("name") == "a b.svg");
    CHECK(q.at("options") == "{}");
    CHECK(q.at("x").empty());
    CHECK(q.at("bad") == "%zz 1");
    CHECK(cookie_value("a=1; pathstream_token=s3; b=2", "pathstream_token") == "s3");
    CHECK(cookie_value("xpathstream_token=s3", "pathstream_token").empty());
    CHECK(cookie_value("pathstream_token", "pathstream_token").empty());
}
