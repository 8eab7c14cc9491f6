#include "access.hpp"

#include <charconv>
#include <stdexcept>

namespace pathstream::host::serve {
namespace {

// Host header without its port: "127.0.0.1:8080" -> "127.0.0.1", "[::1]:80" -> "[::1]".
std::pair<std::string, std::string> split_host_port(const std::string& host) {
    const std::size_t colon = host.rfind(':');
    if (colon == std::string::npos || host.find(']', colon) != std::string::npos) return {host, ""};
    return {host.substr(0, colon), host.substr(colon + 1)};
}

// Equal strings in a time that does not depend on where they first differ.
bool same_secret(const std::string& a, const std::string& b) {
    if (a.size() != b.size() || b.empty()) return false;  // the length is no secret
    unsigned char diff = 0;
    for (std::size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

}  // namespace

bool is_loopback_host(const std::string& host) {
    if (host == "localhost" || host == "::1" || host == "[::1]") return true;
    if (host.rfind("127.", 0) != 0) return false;
    // Four dotted decimals, each 0..255.
    int parts = 0;
    std::size_t at = 0;
    while (at <= host.size()) {
        const std::size_t dot = std::min(host.find('.', at), host.size());
        unsigned value = 0;
        const auto [end, error] = std::from_chars(host.data() + at, host.data() + dot, value);
        if (dot == at || error != std::errc() || end != host.data() + dot || value > 255)
            return false;
        ++parts;
        at = dot + 1;
    }
    return parts == 4;
}

std::optional<std::string> refusal(const AccessPolicy& policy, const RequestFacts& r) {
    const auto [host_name, host_port] = split_host_port(r.host);
    if (policy.loopback) {
        if (!is_loopback_host(host_name) || host_port != std::to_string(policy.port)) {
            return "Host '" + r.host + "' is not this server's loopback address";
        }
    }
    if (!r.origin.empty() && r.origin != "http://" + r.host) {
        return "Origin '" + r.origin + "' is not this server's (http://" + r.host + ")";
    }
    if (r.method == "POST" && r.origin.empty()) return "a POST without an Origin header";
    if (!policy.token.empty()) {
        const std::string bearer = "Bearer ";
        const std::string given = r.authorization.rfind(bearer, 0) == 0
                                      ? r.authorization.substr(bearer.size())
                                  : !r.query_token.empty() ? r.query_token
                                                           : r.cookie_token;
        if (!same_secret(given, policy.token)) return "missing or wrong token";
    }
    return std::nullopt;
}

std::optional<std::string> token_cookie(const AccessPolicy& policy, const RequestFacts& request,
                                        const std::string& cookie_name) {
    if (policy.token.empty() || !same_secret(request.query_token, policy.token))
        return std::nullopt;
    return cookie_name + "=" + policy.token + "; Path=/; HttpOnly; SameSite=Strict";
}

std::optional<std::string> token_problem(const std::string& token) {
    if (token.empty()) return "the token is empty";
    for (const char c : token) {
        const auto u = static_cast<unsigned char>(c);
        if (u <= 0x20 || u == 0x7F || c == '"' || c == ',' || c == ';' || c == '\\') {
            return "the token holds a character a cookie cannot carry (controls, space, '\"', ',', "
                   "';', '\\')";
        }
    }
    return std::nullopt;
}

ListenAddress parse_listen_address(const std::string& listen) {
    const std::size_t colon = listen.rfind(':');
    if (colon == std::string::npos || colon == 0 || colon + 1 == listen.size()) {
        throw std::invalid_argument("--listen '" + listen +
                                    "': want HOST:PORT, e.g. 127.0.0.1:8080");
    }
    ListenAddress a;
    a.host = listen.substr(0, colon);
    if (a.host.size() > 2 && a.host.front() == '[' && a.host.back() == ']')
        a.host = a.host.substr(1, a.host.size() - 2);
    const std::string port = listen.substr(colon + 1);
    const auto [end, error] = std::from_chars(port.data(), port.data() + port.size(), a.port);
    if (error != std::errc() || end != port.data() + port.size() || a.port > 65535) {
        throw std::invalid_argument("--listen '" + listen + "': the port must be 0..65535");
    }
    return a;
}

RequestFacts request_facts(const HttpRequest& request) {
    RequestFacts facts;
    facts.method = request.method;
    facts.host = request.header("host");
    facts.origin = request.header("origin");
    facts.authorization = request.header("authorization");
    facts.query_token = request.param("token");
    facts.cookie_token = cookie_value(request.header("cookie"), kTokenCookie);
    return facts;
}

}  // namespace pathstream::host::serve
