// The HTTP/1.1 transport of `pathstream serve` on Boost.Beast: one thread runs every socket
// (accepting, reading, writing, the event streams) and never waits for a handler; handlers run
// on WorkLanes. Every client is bounded: the request head in bytes, fields and time; the body
// in bytes (chunked too) and time; connections per client and in total; an event listener
// that does not read is dropped (docs/serve.md, "Limits").
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "event_hub.hpp"
#include "http_types.hpp"

namespace pathstream::host::serve {

/// What the server does with a request head before anything else: refuse it (the response,
/// sent with the connection closed and the body never read), or let it through with
/// `headers` added to its response.
struct HeadVerdict {
    std::optional<HttpResponse> refusal;
    std::vector<std::pair<std::string, std::string>> headers;
};

/// Checks a request head (no body yet). Runs on the I/O thread: must not block.
using HeadCheck = std::function<HeadVerdict(const HttpRequest&)>;
/// Answers a whole request on a worker; returns early when `cancel` is set (it may then
/// answer anything: nobody reads it). Throwing std::exception answers 500 with its message.
using HttpHandler = std::function<HttpResponse(const HttpRequest&, const CancelToken& cancel)>;
/// The lane a whole request is answered on (it may read the body). Runs on the I/O thread.
using LaneChoice = std::function<Lane(const HttpRequest&)>;

class HttpServer {
public:
    /// Owns no thread until run(). `hub` feeds the event streams (see events()) and must
    /// outlive the server.
    HttpServer(HttpLimits limits, EventHub& hub);
    ~HttpServer();
    HttpServer(const HttpServer&) = delete;
    HttpServer& operator=(const HttpServer&) = delete;

    /// Listens on `host`:`port` (0: any free port) and returns the port. Throws
    /// std::runtime_error naming the address when it cannot.
    unsigned bind(const std::string& host, unsigned port);

    /// Init only, before run(): the head check, and the routes. A request for a path with no
    /// route is passed to `fallback` (GET only) or answered 404.
    void on_head(HeadCheck check);
    void route(const std::string& method, const std::string& path, LaneChoice lane,
               HttpHandler handler);
    void route(const std::string& method, const std::string& path, Lane lane, HttpHandler handler);
    void fallback(HttpHandler handler);
    /// GET `path` answers a server-sent event stream: "retry", the hub's sticky events, then
    /// every event published after them, and a comment when 2 s pass without one.
    void events(const std::string& path);

    /// Serves until stop(): the I/O thread, the workers and the event pump. Blocks; call once.
    void run();
    /// Ends run(): cancels the running handlers, closes every connection. Any thread.
    void stop();

    /// Connections open now (for tests and the limits' figures). Any thread.
    std::size_t connections() const;

    class Impl;

private:
    std::unique_ptr<Impl> impl_;
};

}  // namespace pathstream::host::serve
