// Inside HttpServer: the state the I/O thread keeps (listener, connections, routes) and one
// connection's life (HttpSession). Only http_server.cpp and http_session.cpp include this.
#pragma once

#include <atomic>
#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <chrono>
#include <map>
#include <optional>
#include <thread>

#include "http_head.hpp"
#include "http_server.hpp"
#include "work_lanes.hpp"

namespace pathstream::host::serve {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
using tcp = net::ip::tcp;

using RequestParser = http::request_parser<http::string_body>;

/// Sets the parser's byte limits from `limits` (before the head is read).
void bound_parser(RequestParser& parser, const HttpLimits& limits);
/// The head a parser read (or failed to, `ec`) as the handlers see it, or its refusal.
HeadOutcome head_outcome(beast::error_code ec, const RequestParser& parser,
                         const HttpLimits& limits);

struct HttpRoute {
    std::string method, path;
    LaneChoice lane;
    HttpHandler handler;
};

class HttpSession;

class HttpServer::Impl {
public:
    Impl(HttpLimits limits, EventHub& hub);

    /// The route for a request's method and path; nullptr for none. `other_method` is set
    /// when the path has a route for another method.
    const HttpRoute* find_route(const std::string& method, const std::string& path,
                                bool& other_method) const;
    void accept();
    void admit(tcp::socket socket);
    void pump_events();

    // Read-only once run() starts.
    HttpLimits limits;
    EventHub& hub;
    HeadCheck head_check;
    std::vector<HttpRoute> routes;
    HttpHandler fallback;
    std::string events_path;
    CancelToken stopping;  ///< parent of every request's token

    // The I/O thread's alone.
    std::map<std::uint64_t, HttpSession*> sessions;  ///< every open connection, oldest first
    std::uint64_t next_session = 1;
    std::atomic<std::size_t> open{0};

    WorkLanes lanes;
    net::io_context io{1};
    tcp::acceptor acceptor{io};
    std::thread pump;
};

/// One connection: reads a request head (bounded), checks it, reads the body (bounded),
/// hands the request to its lane and writes the answer; or turns into an event stream. Lives
/// as long as an operation of its own is pending; every member runs on the I/O thread.
class HttpSession : public std::enable_shared_from_this<HttpSession> {
public:
    enum class State { head, body, busy, events, draining, closed };

    HttpSession(HttpServer::Impl& server, tcp::socket socket, std::string client, std::uint64_t id);
    ~HttpSession();

    void start();
    /// Closes the connection now; a running handler is cancelled.
    void close();
    /// Appends events to an event stream (events published after it joined only).
    void push_events(const std::shared_ptr<const std::vector<HubEvent>>& batch);
    /// A comment that keeps an idle event stream open and finds a client that left.
    void push_comment();

    State state() const { return state_; }
    const std::string& client() const { return client_; }

private:
    void read_head();
    void on_head(beast::error_code ec);
    void read_body();
    void on_body(beast::error_code ec);
    void dispatch();
    void watch();
    void on_watch(beast::error_code ec, std::size_t bytes);
    void answer(HttpResponse response);
    void refuse(int status, const std::string& message);
    void write(HttpResponse response, bool keep_alive);
    void drain();
    void start_events();
    void flush_events();
    void listen_for_close();

    HttpServer::Impl& server_;
    beast::tcp_stream stream_;
    std::string client_;
    std::uint64_t id_;
    State state_ = State::head;
    beast::flat_buffer buffer_;
    std::optional<RequestParser> parser_;
    HttpRequest request_;
    const HttpRoute* route_ = nullptr;
    std::vector<std::pair<std::string, std::string>> extra_headers_;
    CancelToken cancel_;
    bool watching_ = false, client_gone_ = false;
    std::optional<HttpResponse> pending_;
    http::response<http::string_body> response_;
    std::string interim_;
    std::size_t drained_ = 0;
    // An event stream: what is being written, what waits behind it, the last event sent.
    std::string events_writing_, events_waiting_;
    std::uint64_t events_after_ = 0;
};

}  // namespace pathstream::host::serve
