// The web server's request heads, as a client sends them first: read under the server's limits
// into the request the handlers see, or refused with 400, 413 or 431 and a reason; and the
// access check on the result, which lets no request through without the token.
#include <string>
#include <string_view>

#include "fuzz_support.hpp"
#include "serve/access.hpp"
#include "serve/http_head.hpp"

namespace {

using namespace pathstream;
using namespace pathstream::host::serve;

constexpr const char* kToken = "t0k3n";

void check_request(const HttpRequest& r, const HttpLimits& limits) {
    if (r.method.empty()) fuzz::violated("a request without a method");
    if (r.path.find('?') != std::string::npos) fuzz::violated("a path with its query");
    if (r.target.rfind(r.path, 0) != 0) fuzz::violated("a path that is not the target's start");
    if (r.headers.size() > limits.header_fields) fuzz::violated("more fields than the limit");
    for (const auto& [name, value] : r.headers) {
        for (const char c : name) {
            if (c >= 'A' && c <= 'Z') fuzz::violated("a field name not in lower case");
        }
    }
    // The access check of a server beyond loopback: through only with the token.
    AccessPolicy policy;
    policy.loopback = false;
    policy.port = 8080;
    policy.token = kToken;
    const RequestFacts facts = request_facts(r);
    if (!refusal(policy, facts) && facts.authorization != std::string("Bearer ") + kToken &&
        facts.query_token != kToken && facts.cookie_token != kToken) {
        fuzz::violated("a request without the token let through");
    }
    if (const auto cookie = token_cookie(policy, facts, kTokenCookie);
        cookie && cookie->find(kToken) == std::string::npos) {
        fuzz::violated("a cookie that is not the server's token");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    HttpLimits limits;
    limits.header_bytes = 2048;
    limits.header_fields = 16;
    limits.body_bytes = 4096;
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    const HeadOutcome head = parse_request_head(bytes, limits);
    if (!head.complete) return 0;
    if (head.status == 0) {
        check_request(head.request, limits);
    } else if (head.status != 400 && head.status != 413 && head.status != 431) {
        fuzz::violated("refused with status " + std::to_string(head.status));
    } else if (head.reason.empty()) {
        fuzz::violated("a refusal without a reason");
    }
    return 0;
}
