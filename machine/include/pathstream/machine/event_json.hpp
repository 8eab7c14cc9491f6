// The JSON of one log or event line, and its time stamp: what the host's events (docs/events.md)
// and the device runtime's --log-json share, so that both write the same fields the same way.
#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

namespace pathstream::host {

/// One NDJSON line's object; keys keep the order they were added in.
using EventJson = nlohmann::ordered_json;

/// `t` as ISO-8601 UTC with milliseconds: "2025-01-31T12:34:56.789Z". Any context; allocates.
std::string iso8601_utc(std::chrono::system_clock::time_point t);

}  // namespace pathstream::host
