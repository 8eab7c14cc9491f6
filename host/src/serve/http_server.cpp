#include "http_server.hpp"

#include <stdexcept>

#include "http_server_impl.hpp"

namespace pathstream::host::serve {

HttpServer::Impl::Impl(HttpLimits l, EventHub& h)
    : limits(l), hub(h), lanes({2, 4, 2}, l.queued_requests) {}

const HttpRoute* HttpServer::Impl::find_route(const std::string& method, const std::string& path,
                                              bool& other_method) const {
    other_method = false;
    for (const HttpRoute& r : routes) {
        if (r.path != path) continue;
        if (r.method == method) return &r;
        other_method = true;
    }
    return nullptr;
}

void HttpServer::Impl::accept() {
    acceptor.async_accept(net::make_strand(io), [this](beast::error_code ec, tcp::socket socket) {
        if (ec == net::error::operation_aborted || !acceptor.is_open()) return;
        if (!ec) admit(std::move(socket));
        accept();
    });
}

// A new connection within the caps. At a cap, the oldest connection of the same client (or of
// any, for the total) that is only waiting for a request head makes room: a request that
// arrives is always read, so that a stop gets through however many clients sit idle.
void HttpServer::Impl::admit(tcp::socket socket) {
    beast::error_code ec;
    const tcp::endpoint peer = socket.remote_endpoint(ec);
    if (ec) return;
    const std::string client = peer.address().to_string();
    std::size_t mine = 0;
    for (const auto& [id, s] : sessions) mine += s->client() == client ? 1 : 0;
    const bool over_client = mine >= limits.connections_per_client;
    const bool over_total = sessions.size() >= limits.connections;
    if (over_client || over_total) {
        HttpSession* idle = nullptr;
        for (const auto& [id, s] : sessions) {
            if (s->state() == HttpSession::State::head && (!over_client || s->client() == client)) {
                idle = s;
                break;
            }
        }
        if (!idle) return;  // every slot is busy with a request or an event stream: refused
        idle->close();
    }
    const std::uint64_t id = next_session++;
    std::make_shared<HttpSession>(*this, std::move(socket), client, id)->start();
}

// Moves the hub's events to the event streams on the I/O thread; a comment when 2 s pass
// without one.
void HttpServer::Impl::pump_events() {
    std::uint64_t after = hub.published();
    while (!stopping.cancelled()) {
        auto batch = std::make_shared<std::vector<HubEvent>>(
            hub.wait_after(after, std::chrono::milliseconds(2000)));
        if (stopping.cancelled()) return;
        if (!batch->empty()) after = batch->back().sequence;
        net::post(io,
                  [this, batch = std::shared_ptr<const std::vector<HubEvent>>(std::move(batch))] {
                      for (const auto& [id, s] : sessions) {
                          if (s->state() != HttpSession::State::events) continue;
                          batch->empty() ? s->push_comment() : s->push_events(batch);
                      }
                  });
    }
}

HttpServer::HttpServer(HttpLimits limits, EventHub& hub)
    : impl_(std::make_unique<Impl>(limits, hub)) {}

HttpServer::~HttpServer() {
    stop();
    if (impl_->pump.joinable()) impl_->pump.join();
    impl_->lanes.shutdown();
}

unsigned HttpServer::bind(const std::string& host, unsigned port) {
    Impl& s = *impl_;
    beast::error_code ec;
    const net::ip::address address = net::ip::make_address(host, ec);
    if (ec) throw std::runtime_error("serve: cannot listen on " + host + ": not an IP address");
    const tcp::endpoint endpoint(address, static_cast<unsigned short>(port));
    const std::string where = host + ":" + std::to_string(port);
    s.acceptor.open(endpoint.protocol(), ec);
    // SO_REUSEADDR only lets a restart take a port left in TIME_WAIT; never SO_REUSEPORT, with
    // which a second server could share the port and start the wrong machine.
    if (!ec) s.acceptor.set_option(net::socket_base::reuse_address(true), ec);
    if (!ec) s.acceptor.bind(endpoint, ec);
    if (!ec) s.acceptor.listen(net::socket_base::max_listen_connections, ec);
    if (ec)
        throw std::runtime_error("serve: cannot listen on " + where + " (" + ec.message() + ")");
    return s.acceptor.local_endpoint().port();
}

void HttpServer::on_head(HeadCheck check) {
    impl_->head_check = std::move(check);
}

void HttpServer::route(const std::string& method, const std::string& path, LaneChoice lane,
                       HttpHandler handler) {
    impl_->routes.push_back({method, path, std::move(lane), std::move(handler)});
}

void HttpServer::route(const std::string& method, const std::string& path, Lane lane,
                       HttpHandler handler) {
    route(
        method, path, [lane](const HttpRequest&) { return lane; }, std::move(handler));
}

void HttpServer::fallback(HttpHandler handler) {
    impl_->fallback = std::move(handler);
}

void HttpServer::events(const std::string& path) {
    impl_->events_path = path;
}

void HttpServer::run() {
    Impl& s = *impl_;
    if (s.stopping.cancelled()) return;
    s.accept();
    s.pump = std::thread([&s] { s.pump_events(); });
    s.io.run();
}

void HttpServer::stop() {
    Impl& s = *impl_;
    if (s.stopping.cancelled()) return;
    s.stopping.cancel();
    net::post(s.io, [&s] {
        beast::error_code ignored;
        s.acceptor.close(ignored);
        for (const auto& [id, session] : s.sessions) session->close();
        s.io.stop();
    });
}

std::size_t HttpServer::connections() const {
    return impl_->open.load();
}

}  // namespace pathstream::host::serve
