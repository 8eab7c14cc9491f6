// Job messages are read whole and checked field by field: a job that is wrong in any way is
// refused with its reason before a byte of it is stored.
#include "job_message.hpp"

#include <stdexcept>

#include "pathstream/host/fleet_view.hpp"

namespace pathstream::host::serve {
namespace {

bool ends_with(const std::string& s, const std::string& tail) {
    return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// The extensions the readers take (docs/formats.md); anything else would fail only later.
bool known_extension(const std::string& file) {
    for (const char* e : {".json", ".csv", ".svg", ".ngc", ".gcode", ".nc", ".bpt"}) {
        if (ends_with(file, e)) return true;
    }
    return false;
}

std::string string_field(const nlohmann::json& j, const char* key) {
    if (!j.contains(key)) throw std::invalid_argument(std::string("job: no \"") + key + "\"");
    if (!j[key].is_string())
        throw std::invalid_argument(std::string("job: \"") + key + "\" must be a string");
    return j[key].get<std::string>();
}

}  // namespace

void check_job_id(const std::string& id) {
    if (id.empty() || id.size() > 64)
        throw std::invalid_argument("job: \"id\" must have 1 to 64 characters");
    if (!is_fleet_name(id)) {
        throw std::invalid_argument("job: \"id\" \"" + id +
                                    "\": only letters, digits, _ and - (it is a topic level)");
    }
}

JobMessage parse_job_message(const std::string& payload, std::size_t max_drawing_bytes) {
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(payload);
    } catch (const nlohmann::json::exception&) {
        throw std::invalid_argument("job: not JSON");
    }
    if (!j.is_object()) throw std::invalid_argument("job: want a JSON object");
    JobMessage job;
    job.id = string_field(j, "id");
    check_job_id(job.id);
    job.file = string_field(j, "file");
    if (job.file.empty() || job.file.size() > 255 || job.file.find('/') != std::string::npos ||
        job.file.find('\\') != std::string::npos || job.file.front() == '.') {
        throw std::invalid_argument("job: \"file\" must be a plain file name (no directory)");
    }
    if (!known_extension(job.file)) {
        throw std::invalid_argument(
            "job: \"file\" \"" + job.file +
            "\": no reader takes it (.json .csv .svg .ngc .gcode .nc .bpt)");
    }
    job.drawing = string_field(j, "drawing");
    if (job.drawing.size() > max_drawing_bytes) {
        throw std::invalid_argument("job: the drawing has " + std::to_string(job.drawing.size()) +
                                    " bytes, more than the " + std::to_string(max_drawing_bytes) +
                                    " this machine takes");
    }
    job.options = j.value("options", nlohmann::json::object());
    if (!job.options.is_object()) throw std::invalid_argument("job: \"options\" must be an object");
    if (j.contains("bounces")) {
        if (!j["bounces"].is_number_unsigned() || j["bounces"].get<std::uint64_t>() > 1000000)
            throw std::invalid_argument("job: \"bounces\" must be a count");
        job.bounces = j["bounces"].get<unsigned>();
    }
    if (j.contains("submitted") && j["submitted"].is_number())
        job.submitted = j["submitted"].get<double>();
    return job;
}

std::string job_message_text(const JobMessage& job) {
    nlohmann::json text{{"id", job.id},
                        {"file", job.file},
                        {"drawing", job.drawing},
                        {"options", job.options},
                        {"bounces", job.bounces}};
    // The submission time goes along: the job's history starts there on whichever machine.
    if (job.submitted >= 0) text["submitted"] = job.submitted;
    return text.dump();
}

}  // namespace pathstream::host::serve
