// One job at a time, taken from the broker. A machine stays in its queues' shared
// subscriptions even while busy: a shared subscription with no subscriber drops what is
// published to it (MQTT 5, 4.8.2), so a fleet whose machines all left while busy would lose
// every job submitted meanwhile. A busy machine passes a job on instead, after a pause that
// doubles with each pass (0.1 s up to 2 s), so that a full fleet keeps its jobs circulating
// slowly rather than fast.
#include "job_desk.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "pathstream/host/mqtt_client.hpp"

namespace pathstream::host::serve {

namespace fs = std::filesystem;

namespace {

constexpr std::size_t kMaxInbox = 64;  // messages waiting for the desk's thread
constexpr std::size_t kMaxInboxBytes = 64u << 20;
constexpr std::size_t kMaxSeen = 4096;  // job ids remembered against duplicates

// The id of a message that is not a good job, when it has one we can name it by.
std::string id_of(const std::string& payload) {
    try {
        const nlohmann::json j = nlohmann::json::parse(payload);
        if (j.is_object() && j.contains("id") && j["id"].is_string()) {
            const std::string id = j["id"].get<std::string>();
            check_job_id(id);
            return id;
        }
    } catch (const std::exception&) {
    }
    return "";
}

}  // namespace

double unix_seconds() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
        .count();
}

JobDesk::JobDesk(std::string name, std::string kind, std::string state_dir,
                 std::size_t max_drawing_bytes, JobDeskHooks hooks)
    : name_(std::move(name)),
      kind_(std::move(kind)),
      state_file_((fs::path(state_dir) / "mqtt_job.json").string()),
      inbox_dir_((fs::path(state_dir) / "mqtt_inbox").string()),
      max_drawing_bytes_(max_drawing_bytes),
      hooks_(std::move(hooks)),
      job_(nullptr) {
    // Ready before the connection: a resumed session delivers at once, before start().
    std::error_code error;
    fs::create_directories(inbox_dir_, error);
    for (const auto& file : inbox_files()) next_file_ = std::max(next_file_, file.first + 1);
}

std::vector<std::pair<std::uint64_t, std::string>> JobDesk::inbox_files() const {
    std::vector<std::pair<std::uint64_t, std::string>> files;
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(inbox_dir_, error)) {
        const std::string stem = entry.path().stem().string();
        if (entry.path().extension() != ".msg" || stem.empty() ||
            stem.find_first_not_of("0123456789") != std::string::npos || stem.size() > 18)
            continue;
        files.emplace_back(std::stoull(stem), entry.path().string());
    }
    std::sort(files.begin(), files.end());
    return files;
}

JobDesk::~JobDesk() {
    stop();
}

std::vector<std::string> JobDesk::filters() const {
    std::vector<std::string> f = {"pathstream/" + name_ + "/jobs",
                                  "$share/pathstream-any/pathstream/queue/any"};
    if (kind_ != "any") f.push_back("$share/pathstream-" + kind_ + "/pathstream/queue/" + kind_);
    return f;
}

bool JobDesk::is_queue(const std::string& topic) const {
    return topic == "pathstream/queue/any" || topic == "pathstream/queue/" + kind_;
}

void JobDesk::start() {
    std::ifstream in(state_file_);
    if (in) {
        std::stringstream text;
        text << in.rdbuf();
        try {
            nlohmann::json j = nlohmann::json::parse(text.str());
            if (j.is_object() && j.contains("id") && j["id"].is_string() && j.contains("history") &&
                j["history"].is_array()) {
                const std::lock_guard lock(mutex_);
                job_ = std::move(j);
                seen_.insert(job_["id"].get<std::string>());
                seen_order_.push_back(job_["id"].get<std::string>());
            }
        } catch (const std::exception&) {
            std::fprintf(stderr, "pathstream: warning: %s is not a job record: ignored\n",
                         state_file_.c_str());
        }
    }
    bool interrupted = false, held = false;
    {
        const std::lock_guard lock(mutex_);
        held = !job_.is_null() && job_.value("state", "") == "held";
        interrupted = !job_.is_null() && !held;
    }
    if (interrupted) {
        set_state("interrupted",
                  "the machine's host stopped during the job; resume_job "
                  "continues it from where the device rests");
    } else if (held) {
        set_state("held", "");  // announced again: a watcher that came later sees it
    }
    // Jobs the broker delivered to the host that died, oldest first, before those that came
    // since the connection (queued already, their files among these).
    std::deque<Received> left;
    for (const auto& file : inbox_files()) {
        const std::string& path = file.second;
        {
            const std::lock_guard lock(mutex_);
            const bool queued = std::any_of(inbox_.begin(), inbox_.end(),
                                            [&](const Received& r) { return r.file == path; });
            if (queued) continue;
        }
        std::ifstream message(path, std::ios::binary);
        std::string topic;
        std::getline(message, topic);
        std::stringstream payload;
        payload << message.rdbuf();
        left.push_back({topic, payload.str(), path});
    }
    {
        const std::lock_guard lock(mutex_);
        for (const Received& r : left) inbox_bytes_ += r.payload.size();
        inbox_.insert(inbox_.begin(), left.begin(), left.end());
    }
    thread_ = std::thread([this] { work(); });
}

void JobDesk::stop() {
    {
        const std::lock_guard lock(mutex_);
        stopping_ = true;
    }
    changed_.notify_all();
    if (!thread_.joinable()) return;
    thread_.join();
    // Queued jobs not looked at go back to their queue for another machine; this machine's own
    // stay in its inbox for its next start.
    std::deque<Received> left;
    {
        const std::lock_guard lock(mutex_);
        left.swap(inbox_);
        inbox_bytes_ = 0;
    }
    for (const Received& r : left) {
        if (!is_queue(r.topic)) continue;
        try {
            if (pass_back(r.topic, parse_job_message(r.payload, max_drawing_bytes_)) &&
                !r.file.empty()) {
                std::error_code ignored;
                fs::remove(r.file, ignored);
            }
        } catch (const std::invalid_argument&) {
            std::error_code ignored;
            fs::remove(r.file, ignored);  // not a job: nobody can take it
        }
    }
}

void JobDesk::on_message(const std::string& topic, const std::string& payload) {
    {
        const std::lock_guard lock(mutex_);
        if (inbox_.size() >= kMaxInbox || inbox_bytes_ + payload.size() > kMaxInboxBytes) {
            ++dropped_;
            std::fprintf(stderr,
                         "pathstream: warning: %zu jobs wait already: one on %s dropped here\n",
                         inbox_.size(), topic.c_str());
            return;
        }
        // Kept until handled: a host that dies with jobs waiting here finds them at its next
        // start and passes them on, so the broker's one delivery is not lost with it.
        const std::string file =
            (fs::path(inbox_dir_) / (std::to_string(next_file_++) + ".msg")).string();
        std::ofstream out(file, std::ios::binary | std::ios::trunc);
        out << topic << '\n' << payload;
        out.flush();
        inbox_bytes_ += payload.size();
        inbox_.push_back({topic, payload, out ? file : std::string()});
    }
    changed_.notify_all();
}

void JobDesk::work() {
    for (;;) {
        Received r;
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] { return stopping_ || !inbox_.empty(); });
            if (stopping_) return;
            r = std::move(inbox_.front());
            inbox_.pop_front();
            inbox_bytes_ -= r.payload.size();
        }
        try {
            if (handle(r) && !r.file.empty()) {
                std::error_code ignored;
                fs::remove(r.file, ignored);
            }
        } catch (const MqttError& e) {
            std::fprintf(stderr, "pathstream: warning: job on %s: %s\n", r.topic.c_str(), e.what());
        }
    }
}

bool JobDesk::handle(const Received& r) {
    JobMessage job;
    try {
        job = parse_job_message(r.payload, max_drawing_bytes_);
    } catch (const std::invalid_argument& e) {
        const std::string id = id_of(r.payload);
        {
            const std::lock_guard lock(mutex_);
            ++dropped_;
        }
        std::fprintf(stderr, "pathstream: warning: a job on %s refused: %s\n", r.topic.c_str(),
                     e.what());
        if (!id.empty()) {
            publish_state(nlohmann::json{{"id", id},
                                         {"state", "failed"},
                                         {"machine", name_},
                                         {"file", ""},
                                         {"at", unix_seconds()},
                                         {"error", e.what()},
                                         {"history", nlohmann::json::array()}});
        }
        return true;
    }
    bool free = false;
    {
        const std::lock_guard lock(mutex_);
        if (seen_.count(job.id) != 0) return true;  // delivered twice (QoS 1): taken already
        free = job_.is_null() && !hooks_.busy();
        if (free) {
            nlohmann::json history = nlohmann::json::array();
            if (job.submitted >= 0)
                history.push_back(
                    {{"state", "queued"}, {"machine", nullptr}, {"at", job.submitted}});
            job_ = nlohmann::json{{"id", job.id},      {"state", "taken"},     {"machine", name_},
                                  {"file", job.file},  {"at", unix_seconds()}, {"error", ""},
                                  {"history", history}};
            seen_.insert(job.id);
            seen_order_.push_back(job.id);
            if (seen_order_.size() > kMaxSeen) {
                seen_.erase(seen_order_.front());
                seen_order_.pop_front();
            }
        }
    }
    if (!free) {
        if (!is_queue(r.topic)) {
            publish_state(nlohmann::json{{"id", job.id},
                                         {"state", "refused"},
                                         {"machine", name_},
                                         {"file", job.file},
                                         {"at", unix_seconds()},
                                         {"error", "busy: machine " + name_ + " has a job"},
                                         {"history", nlohmann::json::array()}});
            return true;
        }
        // Passed back after a pause, so that a fleet with every machine busy does not spin (at
        // once when the desk stops: the job must not wait for this machine's return).
        const double pause_s =
            std::min(2.0, 0.1 * static_cast<double>(1u << std::min(job.bounces, 5u)));
        {
            std::unique_lock lock(mutex_);
            changed_.wait_for(lock, std::chrono::duration<double>(pause_s),
                              [&] { return stopping_; });
            ++passed_back_;
        }
        return pass_back(r.topic, job);
    }
    save();
    const auto [status, body] = run_started([&] { return hooks_.start(job); });
    if (status != 200) {
        const std::string error =
            body.is_object() && body.contains("error") && body["error"].is_string()
                ? body["error"].get<std::string>()
                : "the job could not start (status " + std::to_string(status) + ")";
        set_state("failed", error);
    }
    return true;
}

bool JobDesk::pass_back(const std::string& topic, JobMessage job) {
    ++job.bounces;
    // The broker has acknowledged the job to this machine: it must get it back.
    for (int attempt = 1;; ++attempt) {
        try {
            hooks_.publish(topic, job_message_text(job), 1, false);
            return true;
        } catch (const MqttError& e) {
            if (attempt == 5) {
                std::fprintf(stderr,
                             "pathstream: warning: job %s not passed back (%s): kept for the "
                             "next start\n",
                             job.id.c_str(), e.what());
                return false;
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(200 * attempt));
        }
    }
}

void JobDesk::job_ended(const std::string& outcome, int exit_code, const std::string& error) {
    {
        const std::lock_guard lock(mutex_);
        // A stream that ends before its start was answered: the end waits for the answer.
        if (starting_) {
            early_end_ = End{outcome, exit_code, error};
            return;
        }
        if (job_.is_null() || job_.value("state", "") != "running") return;  // a page's job
    }
    finish(End{outcome, exit_code, error});
}

void JobDesk::finish(const End& end) {
    if (end.outcome == "finished" && end.exit_code == 0) {
        set_state("done", "");
    } else if (end.outcome == "held") {
        set_state("held", "held by the operator: resume_job continues it, drop_job gives it up");
    } else if (end.outcome == "stopped") {
        set_state("stopped", end.error);
    } else {
        set_state("failed", end.error.empty()
                                ? "the stream ended with exit code " + std::to_string(end.exit_code)
                                : end.error);
    }
}

std::pair<int, nlohmann::json> JobDesk::run_started(
    const std::function<std::pair<int, nlohmann::json>()>& start) {
    {
        const std::lock_guard lock(mutex_);
        starting_ = true;
        early_end_.reset();
    }
    auto answer = start();
    std::optional<End> ended;
    {
        const std::lock_guard lock(mutex_);
        starting_ = false;
        ended.swap(early_end_);
    }
    if (answer.first == 200) {
        set_state("running", "");
        if (ended) finish(*ended);
    }
    return answer;
}

std::pair<int, nlohmann::json> JobDesk::resume_job() {
    std::string state;
    {
        const std::lock_guard lock(mutex_);
        if (!job_.is_null()) state = job_.value("state", "");
    }
    if (state != "held" && state != "interrupted") {
        return {409, {{"ok", false}, {"error", "no held or interrupted job on this machine"}}};
    }
    return run_started(hooks_.resume);
}

std::pair<int, nlohmann::json> JobDesk::drop_job() {
    std::string state;
    {
        const std::lock_guard lock(mutex_);
        if (!job_.is_null()) state = job_.value("state", "");
    }
    if (state != "held" && state != "interrupted") {
        return {409, {{"ok", false}, {"error", "no held or interrupted job on this machine"}}};
    }
    set_state("dropped", "dropped by the operator");
    return {200, {{"ok", true}}};
}

std::string JobDesk::current() const {
    const std::lock_guard lock(mutex_);
    return job_.is_null() ? "" : job_["id"].get<std::string>();
}

std::uint64_t JobDesk::passed_back() const {
    const std::lock_guard lock(mutex_);
    return passed_back_;
}

std::uint64_t JobDesk::dropped() const {
    const std::lock_guard lock(mutex_);
    return dropped_;
}

void JobDesk::set_state(const std::string& state, const std::string& error) {
    nlohmann::json record;
    {
        const std::lock_guard lock(mutex_);
        if (job_.is_null()) return;
        const double at = unix_seconds();
        job_["state"] = state;
        job_["at"] = at;
        job_["error"] = error;
        job_["history"].push_back({{"state", state}, {"machine", name_}, {"at", at}});
        record = job_;
        // A job that ended leaves the machine free; one held or interrupted stays in hand.
        if (state == "done" || state == "failed" || state == "stopped" || state == "dropped")
            job_ = nullptr;
    }
    save();
    publish_state(record);
}

void JobDesk::publish_state(const nlohmann::json& record) {
    const std::string topic = "pathstream/jobs/" + record["id"].get<std::string>() + "/state";
    try {
        hooks_.publish(topic, record.dump(), 1, true);
    } catch (const MqttError& e) {
        // The job goes on; its next state, or the record on disk at the next start, tells.
        std::fprintf(stderr, "pathstream: warning: %s not published: %s\n", topic.c_str(),
                     e.what());
    }
}

void JobDesk::save() const {
    nlohmann::json record;
    {
        const std::lock_guard lock(mutex_);
        record = job_;
    }
    std::error_code ignored;
    if (record.is_null()) {
        fs::remove(state_file_, ignored);
        return;
    }
    // Written whole and renamed: a crash leaves the old record or the new, never half of one.
    const std::string partial = state_file_ + ".partial";
    {
        std::ofstream out(partial, std::ios::trunc);
        out << record.dump() << '\n';
        if (!out.flush()) return;
    }
    fs::rename(partial, state_file_, ignored);
}

}  // namespace pathstream::host::serve
