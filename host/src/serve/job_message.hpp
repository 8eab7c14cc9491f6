// A job from the broker's queue or a machine's own jobs topic, read and checked before anything
// is stored or planned (docs/mqtt.md, "Jobs: a queue on the broker").
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace pathstream::host::serve {

/// A job message's parts, checked.
struct JobMessage {
    std::string id;          ///< 1 to 64 of A-Z a-z 0-9 _ - (a topic level)
    std::string file;        ///< the drawing's file name: its extension chooses the reader
    std::string drawing;     ///< the file's bytes
    nlohmann::json options;  ///< placement and order options, as POST /api/run takes them
    unsigned bounces = 0;    ///< times a busy machine passed it back to its queue
    double submitted = -1;   ///< when it was submitted (s since the epoch); < 0: not said
};

/// Throws std::invalid_argument unless `id` is 1 to 64 of A-Z a-z 0-9 _ -. Cost: O(size).
void check_job_id(const std::string& id);

/// Reads a job message (a JSON object, docs/mqtt.md). Throws std::invalid_argument naming the
/// field and what is wrong: not JSON, a missing or mistyped field, a bad id, a file name with a
/// directory or an extension no reader takes, a drawing over `max_drawing_bytes`. Cost:
/// O(payload); the payload's size is bounded by the broker's and the caller's limits.
JobMessage parse_job_message(const std::string& payload, std::size_t max_drawing_bytes);

/// The message again, with `bounces` counted: what a busy machine puts back on the queue.
std::string job_message_text(const JobMessage& job);

}  // namespace pathstream::host::serve
