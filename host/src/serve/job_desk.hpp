// A machine's side of the job queue: which jobs it takes from the broker, what it publishes
// about them, and the job it was running when its host died (docs/mqtt.md, "Jobs").
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "job_message.hpp"

namespace pathstream::host::serve {

/// What the desk needs from the server and the broker.
struct JobDeskHooks {
    /// Stores the drawing and starts streaming it: (200, ...) when it runs, else the status and
    /// {"error": ...}. Desk thread.
    std::function<std::pair<int, nlohmann::json>(const JobMessage&)> start;
    /// Resumes the job's journal: (200, ...) when it runs. Command worker thread.
    std::function<std::pair<int, nlohmann::json>()> resume;
    /// Whether the machine runs any job (one from the page too). Any thread.
    std::function<bool()> busy;
    /// Publishes on the broker; throws MqttError. Never called on the network thread.
    std::function<void(const std::string& topic, const std::string& payload, int qos, bool retain)>
        publish;
};

/// Takes at most one job at a time; jobs reaching a machine that cannot take one go back to
/// their queue. All members are thread-safe.
class JobDesk {
public:
    /// `state_dir` keeps the job in hand (mqtt_job.json) and the jobs received but not yet
    /// handled (mqtt_inbox/) across a crash of the host.
    JobDesk(std::string name, std::string kind, std::string state_dir,
            std::size_t max_drawing_bytes, JobDeskHooks hooks);
    ~JobDesk();
    JobDesk(const JobDesk&) = delete;
    JobDesk& operator=(const JobDesk&) = delete;

    /// The topics to subscribe to: the kind's and the "any" queue (shared subscriptions) and
    /// the machine's own jobs topic.
    std::vector<std::string> filters() const;
    /// Publishes a job left in the state directory by a host that died as `interrupted`, takes
    /// up the jobs it had received and not handled, then starts the desk's thread. Init,
    /// before subscribing.
    void start();
    /// Stops the desk's thread; jobs not yet looked at are lost to this machine only if the
    /// broker has them acknowledged (they were: QoS 1 acknowledges on receipt). Idempotent.
    void stop();

    /// A message on one of filters()' topics. Network thread: keeps a copy on disk (the broker
    /// counts it delivered), queues it and returns.
    void on_message(const std::string& topic, const std::string& payload);
    /// The job's stream ended with `outcome` (finished, held, stopped, failed; empty when it
    /// said none) and `exit_code`. The server's job thread.
    void job_ended(const std::string& outcome, int exit_code, const std::string& error);
    /// Resumes the held or interrupted job (the operator's `resume_job`): status and body.
    std::pair<int, nlohmann::json> resume_job();
    /// Gives up the held or interrupted job (`drop_job`): status and body.
    std::pair<int, nlohmann::json> drop_job();
    /// The id of the job on this machine (running, held or interrupted); empty: none.
    std::string current() const;
    /// Jobs passed back to their queue so far, messages dropped (malformed or over the bound).
    std::uint64_t passed_back() const;
    std::uint64_t dropped() const;

private:
    /// How a job's stream ended.
    struct End {
        std::string outcome;
        int exit_code = 0;
        std::string error;
    };
    /// The state a job's end leads to (done, held, stopped, failed).
    void finish(const End& end);
    /// Runs `start` (a job's stream starting or resuming) and marks the job running when it
    /// does; an end reported while `start` ran is applied after.
    std::pair<int, nlohmann::json> run_started(
        const std::function<std::pair<int, nlohmann::json>()>& start);
    struct Received {
        std::string topic, payload;
        std::string file;  ///< its copy in the inbox directory; removed once handled
    };
    void work();
    /// False when the message must stay in the inbox for the next start.
    bool handle(const Received& r);
    /// Publishes `job` again on its queue `topic`, counted once more. False when it could not.
    bool pass_back(const std::string& topic, JobMessage job);
    /// Records `state` for the job in hand, publishes it retained and keeps it on disk.
    void set_state(const std::string& state, const std::string& error);
    void publish_state(const nlohmann::json& record);
    void save() const;
    bool is_queue(const std::string& topic) const;
    /// The inbox directory's message files (number, path), oldest first.
    std::vector<std::pair<std::uint64_t, std::string>> inbox_files() const;

    std::string name_, kind_, state_file_, inbox_dir_;
    std::uint64_t next_file_ = 0;
    std::size_t max_drawing_bytes_;
    JobDeskHooks hooks_;
    mutable std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<Received> inbox_;
    std::size_t inbox_bytes_ = 0;
    std::set<std::string> seen_;  ///< ids taken, newest kept (bounded)
    std::deque<std::string> seen_order_;
    nlohmann::json job_;  ///< the job in hand's state record; null: none
    std::uint64_t passed_back_ = 0, dropped_ = 0;
    bool stopping_ = false;
    bool starting_ = false;         ///< a stream is being started: its end waits
    std::optional<End> early_end_;  ///< the end of a stream that ended while starting_
    std::thread thread_;
};

/// Seconds since the epoch, for the states' "at".
double unix_seconds();

}  // namespace pathstream::host::serve
