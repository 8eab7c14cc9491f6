#include "http_head.hpp"

#include "http_server_impl.hpp"

namespace pathstream::host::serve {
namespace {

std::string lower(std::string text) {
    for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return text;
}

}  // namespace

std::string megabytes_text(std::size_t bytes) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g MB", static_cast<double>(bytes) / (1024.0 * 1024.0));
    return text;
}

void bound_parser(RequestParser& parser, const HttpLimits& limits) {
    parser.header_limit(static_cast<std::uint32_t>(limits.header_bytes));
    parser.body_limit(limits.body_bytes);
}

HeadOutcome head_outcome(beast::error_code ec, const RequestParser& parser,
                         const HttpLimits& limits) {
    HeadOutcome out;
    if (ec == http::error::header_limit) {
        out.status = 431;
        out.reason =
            "the request head is larger than " + std::to_string(limits.header_bytes) + " bytes";
        return out;
    }
    if (ec == http::error::body_limit) {  // a Content-Length past the limit: refused before the
                                          // body is sent
        out.status = 413;
        // The parser stops at the length field, before the head is done: the length is read
        // from the field itself.
        const auto field = parser.get().find(http::field::content_length);
        const std::string length = field == parser.get().end() ? "" : std::string(field->value());
        out.reason = "the body is " +
                     (length.find_first_not_of("0123456789") == std::string::npos &&
                              !length.empty() && length.size() < 19
                          ? megabytes_text(static_cast<std::size_t>(std::stoull(length)))
                          : "declared larger") +
                     ", more than the limit of " + megabytes_text(limits.body_bytes);
        return out;
    }
    if (ec) {
        out.status = 400;
        out.reason = "not an HTTP/1.1 request head: " + ec.message();
        return out;
    }
    const auto& head = parser.get();
    std::size_t fields = 0;
    for (const auto& field : head) {
        if (++fields > limits.header_fields) {
            out.status = 431;
            out.reason = "the request has more than " + std::to_string(limits.header_fields) +
                         " header fields";
            return out;
        }
        out.request.headers.emplace_back(lower(std::string(field.name_string())),
                                         std::string(field.value()));
    }
    HttpRequest& r = out.request;
    r.method = std::string(head.method_string());
    r.target = std::string(head.target());
    const std::size_t q = r.target.find('?');
    r.path = r.target.substr(0, q);
    if (q != std::string::npos) r.query = parse_query(r.target.substr(q + 1));
    return out;
}

HeadOutcome parse_request_head(std::string_view bytes, const HttpLimits& limits) {
    RequestParser parser;
    bound_parser(parser, limits);
    parser.eager(false);
    beast::error_code ec;
    std::size_t used = 0;
    while (used < bytes.size() && !parser.is_header_done()) {
        const std::size_t n = parser.put(net::buffer(bytes.data() + used, bytes.size() - used), ec);
        if (ec == http::error::need_more) {
            ec = {};
            HeadOutcome out;
            out.complete = false;
            return out;
        }
        if (ec) break;
        if (n == 0) break;
        used += n;
    }
    if (!ec && !parser.is_header_done()) {
        HeadOutcome out;
        out.complete = false;
        return out;
    }
    return head_outcome(ec, parser, limits);
}

}  // namespace pathstream::host::serve
