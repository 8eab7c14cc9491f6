// Who may use `pathstream serve`: the token and Origin checks every request goes through.
#pragma once

#include <optional>
#include <string>

#include "http_types.hpp"

namespace pathstream::host::serve {

/// What the server was started with, for the checks below. Plain value, read-only once built.
struct AccessPolicy {
    std::string token;     ///< required when non-empty (always when not on loopback)
    bool loopback = true;  ///< listening on 127.0.0.0/8 or ::1 only
    unsigned port = 0;     ///< the port listened on (what a loopback Host header names)
};

/// The parts of one request the checks look at ("" for a header that is absent).
struct RequestFacts {
    std::string method;         ///< "GET", "POST", ...
    std::string host;           ///< Host header
    std::string origin;         ///< Origin header
    std::string authorization;  ///< Authorization header ("Bearer TOKEN")
    std::string query_token;    ///< ?token= (the first page load cannot set headers)
    std::string cookie_token;   ///< the pathstream_token cookie the page got with its first load
};

/// The name of the cookie that carries the token once the page has loaded.
inline constexpr const char* kTokenCookie = "pathstream_token";

/// The facts of `request` the checks look at: its method, Host, Origin and Authorization
/// headers, its ?token= and its kTokenCookie. Task context (the I/O thread); copies the values.
RequestFacts request_facts(const HttpRequest& request);

/// True for "127.x.y.z", "::1", "[::1]" and "localhost": addresses no other machine reaches.
bool is_loopback_host(const std::string& host);

/// Why the request must be refused, or nothing when it may go on. Checks, in order: on
/// loopback, the Host header names a loopback host and the port (a page from elsewhere that
/// rebinds a DNS name to 127.0.0.1 sends its own name); an Origin, when sent, is this
/// server's (http://HOST with the request's Host); a POST carries an Origin (browsers always
/// send one on a POST, so a missing one is not a page's); the token, when one is set, by a
/// Bearer header, ?token= or the cookie, compared in constant time. Cost: a few string compares;
/// any thread.
std::optional<std::string> refusal(const AccessPolicy& policy, const RequestFacts& request);

/// The cookie that keeps the page's token: set only when this request's ?token= is the token
/// (a wrong one, or one sent next to a valid Bearer header, sets nothing), and made of the
/// server's own token, never of the request's bytes. nullopt when none is to be set.
std::optional<std::string> token_cookie(const AccessPolicy& policy, const RequestFacts& request,
                                        const std::string& cookie_name);

/// Why `token` cannot be a token (it travels in a cookie and a query): empty, or characters a
/// cookie value cannot hold (controls, space, '"', ',', ';', '\\'); nothing when it can.
std::optional<std::string> token_problem(const std::string& token);

/// Where to listen, from --listen.
struct ListenAddress {
    std::string host;   ///< as given, without the brackets of an IPv6 address
    unsigned port = 0;  ///< 0: any free port
};

/// Splits `listen` ("HOST:PORT", "[::1]:PORT"). Throws std::invalid_argument for a malformed
/// address or port. Pure; any thread.
ListenAddress parse_listen_address(const std::string& listen);

}  // namespace pathstream::host::serve
