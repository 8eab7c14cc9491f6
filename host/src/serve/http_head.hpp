// A request head as the server reads it: Beast's parser bounded by HttpLimits, then the
// request the handlers see, or the status and reason it is refused with. One function for
// the server's connections and for the fuzz target (fuzz/fuzz_http_request.cpp).
#pragma once

#include <string>
#include <string_view>

#include "http_types.hpp"

namespace pathstream::host::serve {

/// What a request head came to: `status` 0 and `request` filled (no body), or an HTTP status
/// (400, 413, 431) and the reason. `complete` is false when the bytes end before the head does.
struct HeadOutcome {
    int status = 0;
    std::string reason;
    bool complete = true;
    HttpRequest request;
};

/// Reads one request head from `bytes` (what a client sent first) under `limits`: as the
/// server does, without the deadlines. Pure; O(bytes) up to limits.header_bytes.
HeadOutcome parse_request_head(std::string_view bytes, const HttpLimits& limits);

/// The megabytes in an error message: "16 MB", "0.5 MB".
std::string megabytes_text(std::size_t bytes);

}  // namespace pathstream::host::serve
