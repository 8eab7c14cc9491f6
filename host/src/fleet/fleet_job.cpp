// Job messages for the fleet: every check a machine would make that can be made before
// publishing is made here, so that a bad submission fails at the submitter with its reason.
#include "pathstream/host/fleet_job.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "pathstream/host/fleet_view.hpp"

namespace pathstream::host {

using Json = nlohmann::json;

namespace {

// The extensions the machines take (docs/mqtt.md), exactly as they check them: a job they would
// refuse is refused here, before it is published.
bool machine_takes(const std::string& file) {
    for (const std::string e : {".json", ".csv", ".svg", ".ngc", ".gcode", ".nc", ".bpt"}) {
        if (file.size() > e.size() && file.compare(file.size() - e.size(), e.size(), e) == 0)
            return true;
    }
    return false;
}

}  // namespace

std::string generate_job_id(double unix_seconds, std::mt19937_64& random) {
    const std::time_t t = static_cast<std::time_t>(std::floor(unix_seconds));
    std::tm utc{};
    ::gmtime_r(&t, &utc);
    char text[48];
    std::snprintf(text, sizeof text, "job-%04d%02d%02d-%02d%02d%02d-%04x", utc.tm_year + 1900,
                  utc.tm_mon + 1, utc.tm_mday, utc.tm_hour, utc.tm_min, utc.tm_sec,
                  static_cast<unsigned>(random() & 0xffffu));
    return text;
}

FleetJobMessages build_fleet_job(const FleetJobSpec& spec, double now, std::mt19937_64& random) {
    if (!spec.id.empty() && !is_fleet_name(spec.id)) {
        throw std::invalid_argument("job id \"" + spec.id.substr(0, 80) +
                                    "\": 1 to 64 of A-Z a-z 0-9 _ - (it is a topic level)");
    }
    if (!spec.kind.empty() && !spec.machine.empty())
        throw std::invalid_argument("a job goes to a kind or to one machine, not both");
    if (!spec.kind.empty() && !is_fleet_name(spec.kind)) {
        throw std::invalid_argument("kind \"" + spec.kind.substr(0, 80) +
                                    "\": 1 to 64 of A-Z a-z 0-9 _ -");
    }
    if (!spec.machine.empty() && !is_fleet_name(spec.machine)) {
        throw std::invalid_argument("machine \"" + spec.machine.substr(0, 80) +
                                    "\": 1 to 64 of A-Z a-z 0-9 _ -");
    }
    const std::string base = spec.file_name.substr(spec.file_name.find_last_of("/\\") + 1);
    if (base.empty() || base.size() > 255 || base.front() == '.')
        throw std::invalid_argument("a job needs a file name (1 to 255 characters, no leading .)");
    if (!machine_takes(base)) {
        throw std::invalid_argument("file \"" + base +
                                    "\": no reader knows its extension (.json .csv .svg .ngc "
                                    ".gcode .nc .bpt)");
    }
    if (spec.drawing.size() > spec.max_bytes) {
        throw std::invalid_argument(
            "file \"" + base + "\": " + std::to_string(spec.drawing.size()) + " bytes, more than " +
            std::to_string(spec.max_bytes) + " a job may carry");
    }
    if (!spec.options.is_object()) throw std::invalid_argument("job options must be an object");

    FleetJobMessages out;
    out.id = spec.id.empty() ? generate_job_id(now, random) : spec.id;
    out.state_topic = "pathstream/jobs/" + out.id + "/state";
    out.message = Json{{"id", out.id},
                       {"file", base},
                       {"drawing", spec.drawing},
                       {"options", spec.options},
                       {"submitted", now}};
    if (spec.machine.empty()) {
        const std::string kind = spec.kind.empty() ? "any" : spec.kind;
        out.topic = "pathstream/queue/" + kind;
        out.message["kind"] = kind;
    } else {
        out.topic = "pathstream/" + spec.machine + "/jobs";
        out.message["machine"] = spec.machine;
    }
    try {
        (void)Json(spec.drawing).dump();
    } catch (const Json::exception&) {
        throw std::invalid_argument("file \"" + base + "\": not UTF-8 text");
    }
    out.state = Json{
        {"id", out.id},
        {"state", "queued"},
        {"machine", nullptr},
        {"file", base},
        {"at", now},
        {"error", ""},
        {"history", Json::array({Json{{"state", "queued"}, {"machine", nullptr}, {"at", now}}})}};
    return out;
}

}  // namespace pathstream::host
