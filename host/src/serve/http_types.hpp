// The HTTP server's vocabulary: its limits, a request as the handlers see it, a response, and
// the cancel token a long handler watches (docs/serve.md, "Limits").
#pragma once

#include <atomic>
#include <chrono>
#include <cstddef>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace pathstream::host::serve {

/// What one client, or all of them, may cost the server. Read-only once the server runs.
struct HttpLimits {
    std::size_t header_bytes = 16 * 1024;  ///< request line and every field together
    std::size_t header_fields = 64;
    std::chrono::milliseconds header_deadline{
        10'000};                         ///< a whole request head, from its first wait
    std::size_t body_bytes = 16u << 20;  ///< counted as it arrives, chunked or not
    std::chrono::milliseconds body_deadline{120'000};
    std::chrono::milliseconds write_deadline{10'000};  ///< one response, or one batch of events
    std::size_t connections = 512;
    std::size_t connections_per_client = 256;
    std::size_t event_streams = 128;
    std::size_t event_backlog_bytes =
        1u << 20;                      ///< unsent events a listener may owe before it is dropped
    std::size_t queued_requests = 64;  ///< per lane, waiting for a worker
};

/// Which workers answer a request: a lane's workers only ever wait for that lane's work, so
/// a long plan or a jog never delays a stop.
enum class Lane {
    stop,     ///< stopping the machine
    command,  ///< state, the other commands, the last preview, the page's files
    work,     ///< uploads, previews, runs, simulations: planning
};

/// A request as the handlers see it: head and whole body. Header names are lower case.
struct HttpRequest {
    std::string method;
    std::string target;                        ///< as sent: path and query
    std::string path;                          ///< without the query
    std::map<std::string, std::string> query;  ///< decoded; the first of a repeated name
    std::vector<std::pair<std::string, std::string>> headers;
    std::string body;
    std::string client;  ///< the peer's address

    /// The first field named `name` (lower case), or "".
    std::string header(const std::string& name) const;
    /// The query parameter `name`, or "".
    std::string param(const std::string& name) const;
    bool has_param(const std::string& name) const { return query.count(name) != 0; }
};

/// A response: status, type, body and extra header fields.
struct HttpResponse {
    int status = 200;
    std::string content_type = "application/json";
    std::string body;
    std::vector<std::pair<std::string, std::string>> headers;
};

/// Set when a handler's answer is no longer wanted: its client went away, a newer request
/// replaced it, or the server stops. Copies share one flag; a token made with a parent is
/// also cancelled by the parent's. Any thread.
class CancelToken {
public:
    CancelToken() : flag_(std::make_shared<std::atomic<bool>>(false)) {}
    /// A token of its own that this one's cancel() also cancels (one level).
    CancelToken child() const {
        CancelToken c;
        c.parent_ = flag_;
        return c;
    }
    void cancel() const { flag_->store(true); }
    bool cancelled() const { return flag_->load() || (parent_ && parent_->load()); }

private:
    std::shared_ptr<std::atomic<bool>> flag_;
    std::shared_ptr<std::atomic<bool>> parent_;
};

/// Splits "a=1&b=x%20y" into decoded names and values ('+' is a space); the first of a
/// repeated name wins. Malformed escapes stay as written. Linear in the text.
std::map<std::string, std::string> parse_query(const std::string& query);

/// The value of cookie `name` in a Cookie header, or "".
std::string cookie_value(const std::string& cookies, const std::string& name);

}  // namespace pathstream::host::serve
