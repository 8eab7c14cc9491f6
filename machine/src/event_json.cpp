#include "pathstream/machine/event_json.hpp"

#include <cstdio>
#include <ctime>

namespace pathstream::host {

std::string iso8601_utc(std::chrono::system_clock::time_point t) {
    const std::time_t seconds = std::chrono::system_clock::to_time_t(t);
    std::tm utc{};
    gmtime_r(&seconds, &utc);
    char text[40];
    const std::size_t n = std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%S", &utc);
    const auto ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(t.time_since_epoch()).count() % 1000;
    std::snprintf(text + n, sizeof text - n, ".%03dZ", static_cast<int>(ms < 0 ? ms + 1000 : ms));
    return text;
}

}  // namespace pathstream::host
