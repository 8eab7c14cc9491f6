// The device's log: one line per event on standard output, stamped with the time (ISO-8601
// UTC, ms); text for people or, with --log-json, NDJSON whose `message` is the text
// (docs/events.md, "The device's log").
#pragma once

#include <string>

#include "pathstream/machine/event_json.hpp"

namespace pathstream::linux_device {

/// Writes the log lines; each is flushed at once. Task context (the device's thread).
class DeviceLog {
public:
    explicit DeviceLog(bool json) : json_(json) {}

    /// One line: `event` names it in NDJSON, `text` is what a person reads, `fields` are the
    /// NDJSON line's other values (after time and event, before message).
    void operator()(const char* event, const std::string& text,
                    const host::EventJson& fields = host::EventJson::object()) const;

private:
    bool json_;
};

}  // namespace pathstream::linux_device
