#include <nlohmann/json.hpp>

#include "http_server_impl.hpp"

namespace pathstream::host::serve {
namespace {

std::string lower(std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

std::string error_json(const std::string& message) {
    return nlohmann::json{{"ok", false}, {"error", message}}.dump();
}

}  // namespace

HttpSession::HttpSession(HttpServer::Impl& server, tcp::socket socket, std::string client,
                         std::uint64_t id)
    : server_(server),
      stream_(std::move(socket)),
      client_(std::move(client)),
      id_(id),
      cancel_(server.stopping.child()) {
    server_.sessions[id_] = this;
    server_.open.fetch_add(1);
}

HttpSession::~HttpSession() {
    cancel_.cancel();
    server_.sessions.erase(id_);
    server_.open.fetch_sub(1);
}

void HttpSession::start() {
    read_head();
}

void HttpSession::close() {
    if (state_ == State::closed) return;
    state_ = State::closed;
    cancel_.cancel();
    beast::error_code ignored;
    stream_.socket().shutdown(tcp::socket::shutdown_both, ignored);
    stream_.socket().close(ignored);
}

// A request head, whole within the deadline and the byte limit (slow or endless heads cost a
// connection slot for at most the deadline).
void HttpSession::read_head() {
    state_ = State::head;
    parser_.emplace();
    bound_parser(*parser_, server_.limits);
    request_ = HttpRequest{};
    route_ = nullptr;
    extra_headers_.clear();
    cancel_ = server_.stopping.child();
    stream_.expires_after(server_.limits.header_deadline);
    http::async_read_header(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_head(ec); });
}

void HttpSession::on_head(beast::error_code ec) {
    if (state_ == State::closed) return;
    if (ec && ec != http::error::header_limit && ec != http::error::body_limit) {
        return close();  // the deadline, the client gone, or not HTTP
    }
    HeadOutcome head = head_outcome(ec, *parser_, server_.limits);
    if (head.status != 0) return refuse(head.status, head.reason);
    request_ = std::move(head.request);
    request_.client = client_;
    if (server_.head_check) {
        HeadVerdict verdict = server_.head_check(request_);
        if (verdict.refusal) {
            write(std::move(*verdict.refusal), false);
            return;
        }
        extra_headers_ = std::move(verdict.headers);
    }
    if (request_.method == "GET" && request_.path == server_.events_path &&
        !server_.events_path.empty()) {
        return start_events();
    }
    bool other_method = false;
    route_ = server_.find_route(request_.method, request_.path, other_method);
    if (!route_ && !(request_.method == "GET" && server_.fallback)) {
        return refuse(other_method ? 405 : 404,
                      other_method ? "method not allowed here" : "no such API path");
    }
    if (const auto length = parser_->content_length();
        length && *length > server_.limits.body_bytes) {
        return refuse(413, "the body is " + megabytes_text(*length) + ", more than the limit of " +
                               megabytes_text(server_.limits.body_bytes));
    }
    if (parser_->is_done()) return dispatch();
    if (lower(request_.header("expect")) == "100-continue") {
        interim_ = "HTTP/1.1 100 Continue\r\n\r\n";
        stream_.expires_after(server_.limits.write_deadline);
        net::async_write(stream_, net::buffer(interim_),
                         [self = shared_from_this()](beast::error_code e, std::size_t) {
                             if (e) return self->close();
                             self->read_body();
                         });
        return;
    }
    read_body();
}

void HttpSession::read_body() {
    state_ = State::body;
    stream_.expires_after(server_.limits.body_deadline);
    http::async_read(
        stream_, buffer_, *parser_,
        [self = shared_from_this()](beast::error_code ec, std::size_t) { self->on_body(ec); });
}

void HttpSession::on_body(beast::error_code ec) {
    if (state_ == State::closed) return;
    if (ec == http::error::body_limit) {
        return refuse(413, "the body is larger than the limit of " +
                               megabytes_text(server_.limits.body_bytes));
    }
    if (ec) return close();
    dispatch();
}

// The whole request to its lane's workers; the connection is watched meanwhile so that a
// client that leaves cancels the work it asked for.
void HttpSession::dispatch() {
    request_.body = std::move(parser_->get().body());
    state_ = State::busy;
    HttpHandler handler = route_ ? route_->handler : server_.fallback;
    const Lane lane = route_ ? route_->lane(request_) : Lane::command;
    auto task = [self = shared_from_this(), handler, request = std::move(request_),
                 cancel = cancel_, executor = stream_.get_executor()]() mutable {
        HttpResponse response;
        try {
            response = handler(request, cancel);
        } catch (const std::exception& e) {
            response = {500, "application/json", error_json(e.what()), {}};
        }
        net::post(executor, [s = std::move(self), r = std::move(response)]() mutable {
            s->answer(std::move(r));
        });
    };
    if (!server_.lanes.submit(lane, std::move(task))) {
        return refuse(503, "the server is busy: too many requests wait; try again");
    }
    watch();
}

void HttpSession::watch() {
    watching_ = true;
    stream_.socket().async_read_some(
        buffer_.prepare(512), [self = shared_from_this()](beast::error_code ec, std::size_t n) {
            self->on_watch(ec, n);
        });
}

void HttpSession::on_watch(beast::error_code ec, std::size_t bytes) {
    watching_ = false;
    if (state_ == State::closed) return;
    buffer_.commit(bytes);  // a pipelined request's first bytes: kept for read_head
    if (ec && ec != net::error::operation_aborted) {
        client_gone_ = true;
        cancel_.cancel();
    }
    if (pending_) {
        HttpResponse r = std::move(*pending_);
        pending_.reset();
        return client_gone_ ? close() : write(std::move(r), parser_->get().keep_alive());
    }
}

void HttpSession::answer(HttpResponse response) {
    if (state_ == State::closed) return;
    if (client_gone_) return close();
    if (watching_) {
        pending_ = std::move(response);
        beast::error_code ignored;
        stream_.socket().cancel(ignored);  // on_watch writes it
        return;
    }
    write(std::move(response), parser_->get().keep_alive());
}

void HttpSession::refuse(int status, const std::string& message) {
    write(HttpResponse{status, "application/json", error_json(message), {}}, false);
}

void HttpSession::write(HttpResponse response, bool keep_alive) {
    response_ = {};
    response_.version(11);
    response_.result(static_cast<unsigned>(response.status));
    response_.set(http::field::content_type, response.content_type);
    for (const auto& [name, value] : extra_headers_) response_.set(name, value);
    for (const auto& [name, value] : response.headers) response_.set(name, value);
    response_.body() = std::move(response.body);
    response_.keep_alive(keep_alive);
    response_.prepare_payload();
    stream_.expires_after(server_.limits.write_deadline);
    http::async_write(stream_, response_,
                      [self = shared_from_this(), keep_alive](beast::error_code ec, std::size_t) {
                          if (ec || self->state_ == State::closed) return self->close();
                          if (!keep_alive) return self->drain();
                          self->read_head();
                      });
}

// Ends a connection whose request was not read to its end: the answer is sent, the rest of
// the request read and dropped for a moment (bounded), so that closing does not reset the
// connection before the client has read the answer.
void HttpSession::drain() {
    if (state_ != State::draining) {
        state_ = State::draining;
        beast::error_code ignored;
        stream_.socket().shutdown(tcp::socket::shutdown_send, ignored);
        stream_.expires_after(std::chrono::seconds(1));
    }
    buffer_.clear();
    stream_.async_read_some(buffer_.prepare(16 * 1024),
                            [self = shared_from_this()](beast::error_code ec, std::size_t n) {
                                self->drained_ += n;
                                if (ec || self->drained_ > (64u << 20)) return self->close();
                                self->drain();
                            });
}

// Server-sent events: a head with no length (the stream ends with the connection), then what
// the hub publishes. Writes are bounded in time and what waits behind them in bytes.
void HttpSession::start_events() {
    std::size_t streams = 0;
    for (const auto& [id, s] : server_.sessions) streams += s->state_ == State::events ? 1 : 0;
    if (streams >= server_.limits.event_streams) {
        return refuse(503, "too many event streams (" + std::to_string(streams) + ")");
    }
    state_ = State::events;
    events_waiting_ = "HTTP/1.1 200 OK\r\nContent-Type: text/event-stream\r\nConnection: close\r\n";
    for (const auto& [name, value] : extra_headers_)
        events_waiting_ += name + ": " + value + "\r\n";
    events_waiting_ += "\r\nretry: 1000\n\n";
    for (const HubEvent& e : server_.hub.sticky(events_after_))
        events_waiting_ += "data: " + e.json + "\n\n";
    flush_events();
    listen_for_close();
}

// An event stream's client sends nothing more: a read that ends is the client gone. The
// pending read also keeps the session alive between events.
void HttpSession::listen_for_close() {
    buffer_.clear();
    stream_.socket().async_read_some(
        buffer_.prepare(1024), [self = shared_from_this()](beast::error_code ec, std::size_t) {
            if (ec) return self->close();
            self->listen_for_close();
        });
}

void HttpSession::push_events(const std::shared_ptr<const std::vector<HubEvent>>& batch) {
    if (state_ != State::events) return;
    for (const HubEvent& e : *batch) {
        if (e.sequence <= events_after_) continue;
        events_waiting_ += "data: " + e.json + "\n\n";
        events_after_ = e.sequence;
    }
    // A listener whose last write is still pending and who owes more than the backlog does not
    // read (or reads slower than the events come): dropped, never waited for.
    if (!events_writing_.empty() && events_waiting_.size() > server_.limits.event_backlog_bytes)
        return close();
    flush_events();
}

void HttpSession::push_comment() {
    if (state_ != State::events) return;
    events_waiting_ += ": idle\n\n";
    flush_events();
}

void HttpSession::flush_events() {
    if (!events_writing_.empty() || events_waiting_.empty() || state_ != State::events) return;
    events_writing_.swap(events_waiting_);
    stream_.expires_after(server_.limits.write_deadline);
    net::async_write(stream_, net::buffer(events_writing_),
                     [self = shared_from_this()](beast::error_code ec, std::size_t) {
                         self->events_writing_.clear();
                         if (ec) return self->close();
                         self->flush_events();
                     });
}

}  // namespace pathstream::host::serve
