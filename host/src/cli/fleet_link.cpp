#include "fleet_link.hpp"

#include <unistd.h>

#include <random>

namespace pathstream::host {
namespace {

// The topics the view describes, state before progress: the broker sends each filter's
// retained messages as it grants it, so a job's state comes before its progress.
const char* const kFilters[] = {"pathstream/+/online",        "pathstream/+/status",
                                "pathstream/+/progress",      "pathstream/jobs/+/state",
                                "pathstream/jobs/+/progress", "pathstream/+/reply"};

constexpr std::size_t kMaxReply = 64 * 1024;

}  // namespace

FleetLink::FleetLink(MqttUrl url) : url_(std::move(url)) {
    std::random_device entropy;
    char id[64];
    std::snprintf(id, sizeof id, "pathstream-fleet-%d-%08x", static_cast<int>(::getpid()),
                  static_cast<unsigned>(entropy()));
    prefix_ = std::string(id) + "-";
    client_ = std::make_unique<MqttClient>(
        url_, id, std::nullopt, [this](const std::string& topic, const std::string& payload) {
            on_message(topic, payload);
        });
}

FleetLink::~FleetLink() {
    // The client first: its network thread calls on_message, which uses the members below.
    disconnect();
    client_.reset();
}

void FleetLink::connect() {
    client_->connect();
    for (const char* f : kFilters) client_->subscribe(f, 1);
}

void FleetLink::disconnect() {
    // Also while reconnecting after a lost connection: this stops the network thread.
    if (client_) client_->disconnect();
}

void FleetLink::on_message(const std::string& topic, const std::string& payload) {
    {
        std::lock_guard lock(mutex_);
        const std::size_t slash = topic.rfind('/');
        if (slash != std::string::npos && topic.compare(slash, std::string::npos, "/reply") == 0) {
            // Only the replies to this watcher's own commands are kept, and only while waited
            // for: another client's replies pass by.
            if (payload.size() > kMaxReply) return;
            nlohmann::json j = nlohmann::json::parse(payload, nullptr, false);
            if (!j.is_object() || !j.contains("id") || !j["id"].is_string()) return;
            const auto it = replies_.find(j["id"].get<std::string>());
            if (it == replies_.end() || it->second) return;
            it->second = std::move(j);
        } else {
            view_.apply(topic, payload);
        }
    }
    changed_.notify_all();
}

void FleetLink::read(const std::function<void(const FleetView&)>& read) const {
    std::lock_guard lock(mutex_);
    read(view_);
}

nlohmann::json FleetLink::view_json() const {
    std::lock_guard lock(mutex_);
    return view_.to_json();
}

bool FleetLink::wait_for(const std::function<bool(const FleetView&)>& done,
                         std::chrono::milliseconds timeout) const {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return done(view_); });
}

void FleetLink::publish(const std::string& topic, const std::string& payload, int qos,
                        bool retain) {
    client_->publish(topic, payload, qos, retain);
}

std::optional<nlohmann::json> FleetLink::command(const std::string& name, nlohmann::json request,
                                                 std::chrono::milliseconds timeout) {
    std::string id;
    {
        std::lock_guard lock(mutex_);
        id = prefix_ + std::to_string(next_command_++);
        replies_[id];  // waited for from now: a quick reply is not missed
    }
    request["id"] = id;
    try {
        client_->publish("pathstream/" + name + "/command", request.dump(), 1, false);
    } catch (...) {
        std::lock_guard lock(mutex_);
        replies_.erase(id);
        throw;
    }
    std::unique_lock lock(mutex_);
    changed_.wait_for(lock, timeout, [&] { return replies_[id].has_value(); });
    std::optional<nlohmann::json> reply = std::move(replies_[id]);
    replies_.erase(id);
    return reply;
}

}  // namespace pathstream::host
