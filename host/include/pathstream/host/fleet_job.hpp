// A job for the fleet's queue as the broker carries it: the job message and its first
// retained state, built from a drawing file and checked before anything is published
// (docs/mqtt.md, "Jobs: a queue on the broker").
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

namespace pathstream::host {

/// What a submitter asks for. `kind` and `machine` exclude each other; neither: kind "any".
struct FleetJobSpec {
    std::string file_name;  ///< the drawing's file name (its extension picks the reader)
    std::string drawing;    ///< the file's text
    std::string kind;       ///< a queue: pathstream/queue/KIND
    std::string machine;    ///< one machine: pathstream/NAME/jobs
    std::string id;         ///< "": generated
    nlohmann::json options = nlohmann::json::object();  ///< placement, as POST /api/run takes
    std::size_t max_bytes = 16u << 20;  ///< the largest drawing (serve's --max-upload-mb)
};

/// What to publish: the job message on `topic` (QoS 1) after the retained `queued` state on
/// `state_topic` (QoS 1), so that a watcher sees the job before a machine can take it.
struct FleetJobMessages {
    std::string id;
    std::string topic;        ///< pathstream/queue/KIND or pathstream/NAME/jobs
    std::string state_topic;  ///< pathstream/jobs/ID/state
    nlohmann::json
        message;           ///< {"id", "file", "drawing", "options", "kind"|"machine", "submitted"}
    nlohmann::json state;  ///< {"id", "state": "queued", "machine": null, "file", "at", ...}
};

/// A fresh id, job-YYYYMMDD-HHMMSS-XXXX (UTC, XXXX four random hex digits): sortable by time,
/// and two submitters in the same second collide once in 65536.
std::string generate_job_id(double unix_seconds, std::mt19937_64& random);

/// Checks the spec and builds the messages, `now` the submission time (s since 1970). Throws
/// std::invalid_argument naming the problem: a bad id ("job id \"a/b\": 1 to 64 of A-Z a-z
/// 0-9 _ -"), an extension no reader knows (naming the known ones), a drawing larger than
/// max_bytes or not UTF-8, a bad kind or machine name, both kind and machine, options that are
/// not an object. Pure but for the random id; any thread.
FleetJobMessages build_fleet_job(const FleetJobSpec& spec, double now, std::mt19937_64& random);

}  // namespace pathstream::host
