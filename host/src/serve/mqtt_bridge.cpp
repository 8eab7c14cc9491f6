// The machine on the broker: sticky state on retained topics (a watcher that comes later sees
// it at once), every event on pathstream/NAME/events, commands answered one at a time.
#include "mqtt_bridge.hpp"

#include <chrono>
#include <stdexcept>

#include "pathstream/host/fleet_view.hpp"

namespace pathstream::host::serve {
namespace {

constexpr std::size_t kMaxQueued = 8;
constexpr std::uint32_t kJobSessionExpiry_s = 24 * 3600;

// The retained topic a hub event's kind updates ("" for none).
std::string retained_leaf(const std::string& json) {
    auto is = [&](const char* kind) {
        return json.find(std::string("\"event\":\"") + kind + "\"") != std::string::npos;
    };
    if (is("device")) return "status";
    if (is("progress")) return "progress";
    for (const char* k : {"job_start", "job_end", "pause", "process", "state"}) {
        if (is(k)) return "job";
    }
    return "";
}

}  // namespace

void check_machine_name(const std::string& name) {
    if (name.empty() || name.size() > 64) {
        throw std::invalid_argument("serve: --name must have 1 to 64 characters");
    }
    if (!is_fleet_name(name)) {
        throw std::invalid_argument("serve: --name \"" + name +
                                    "\": only letters, digits, _ and - (it is part of topics)");
    }
}

MqttBridge::MqttBridge(MqttLink link, EventHub& hub, ControlFunction control,
                       nlohmann::json identity, JobDesk* desk)
    : link_(std::move(link)),
      hub_(hub),
      control_(std::move(control)),
      identity_(std::move(identity)),
      desk_(desk) {}

MqttBridge::~MqttBridge() {
    stop();
}

void MqttBridge::start() {
    nlohmann::json offline = identity_;
    offline["online"] = false;
    client_ = std::make_unique<MqttClient>(
        link_.url, "pathstream-" + link_.name,
        MqttClient::Will{topic("online"), offline.dump(), 1, true},
        [this](const std::string& t, const std::string& payload) {
            // Only the command and the job topics are subscribed;
            // anything else is not ours to act on.
            if (t == topic("command")) {
                on_command(payload);
            } else if (desk_ && (t == topic("jobs") || t.rfind("pathstream/queue/", 0) == 0)) {
                desk_->on_message(t, payload);
            }
        },
        // A machine that takes jobs keeps its session: jobs on their way to it when its host
        // dies wait for its return instead of being dropped (as for a clean session).
        desk_ ? kJobSessionExpiry_s : 0);
    client_->connect();
    client_->subscribe(topic("command"), 1);
    if (desk_) {
        // The job left by a host that died is announced before any other job can come.
        desk_->start();
        for (const std::string& f : desk_->filters()) client_->subscribe(f, 1);
    }
    nlohmann::json online = identity_;
    online["online"] = true;
    client_->publish(topic("online"), online.dump(), 1, true);
    forwarder_ = std::thread([this] { forward(); });
    worker_ = std::thread([this] { answer(); });
}

void MqttBridge::stop() {
    {
        std::lock_guard lock(mutex_);
        if (stopping_ || !client_) return;
        stopping_ = true;
    }
    changed_.notify_all();
    if (forwarder_.joinable()) forwarder_.join();
    if (worker_.joinable()) worker_.join();
    if (desk_) {
        // Out of the queues first, so that no job comes after the desk has passed back what
        // it holds.
        for (const std::string& f : desk_->filters()) {
            if (f.rfind("$share/", 0) != 0) continue;
            try {
                client_->unsubscribe(f);
            } catch (const MqttError&) {
            }
        }
        desk_->stop();
    }
    try {
        nlohmann::json offline = identity_;
        offline["online"] = false;
        client_->publish(topic("online"), offline.dump(), 1, true);
    } catch (const MqttError&) {
        // The broker is gone: the will says the same once it is back.
    }
    client_->disconnect();
}

void MqttBridge::publish(const std::string& t, const std::string& payload, int qos, bool retain) {
    client_->publish(t, payload, qos, retain);
}

void MqttBridge::forward() {
    std::uint64_t after = 0;
    for (const HubEvent& e : hub_.sticky(after)) {
        const std::string leaf = retained_leaf(e.json);
        try {
            if (!leaf.empty()) client_->publish(topic(leaf), e.json, 0, true);
        } catch (const MqttError&) {
        }
    }
    for (;;) {
        bool last = false;
        {
            std::lock_guard lock(mutex_);
            last = stopping_;
        }
        // Once stopping, what the hub still holds goes out without waiting (a stream's
        // job_end comes just before its bridge stops).
        for (const HubEvent& e :
             hub_.wait_after(after, std::chrono::milliseconds(last ? 0 : 200))) {
            after = e.sequence;
            // QoS 0: a status at 10 Hz needs no acknowledgement; the next one replaces it.
            try {
                const std::string leaf = retained_leaf(e.json);
                if (!leaf.empty()) client_->publish(topic(leaf), e.json, 0, true);
                client_->publish(topic("events"), e.json, 0, false);
                // The job's own progress, for whoever follows the job rather than the machine.
                if (leaf == "progress" && desk_) {
                    const std::string id = desk_->current();
                    if (!id.empty())
                        client_->publish("pathstream/jobs/" + id + "/progress", e.json, 0, true);
                }
            } catch (const MqttError&) {
                // Disconnected for a moment: libmosquitto reconnects; the retained topics
                // catch up with the next event of each kind.
            }
        }
        if (last) return;
    }
}

void MqttBridge::on_command(const std::string& payload) {
    bool full = false;
    {
        std::lock_guard lock(mutex_);
        if (commands_.size() >= kMaxQueued) {
            full = true;
        } else {
            commands_.push_back(payload);
        }
    }
    if (full) {
        nlohmann::json id = nullptr;
        try {
            const nlohmann::json j = nlohmann::json::parse(payload);
            if (j.is_object() && j.contains("id")) id = j["id"];
        } catch (const std::exception&) {
        }
        // Answered from the network thread with QoS 0: it must not wait for an acknowledgement.
        try {
            client_->publish(topic("reply"),
                             nlohmann::json{{"id", id},
                                            {"ok", false},
                                            {"status", 503},
                                            {"error", "busy: 8 commands are waiting already"}}
                                 .dump(),
                             0, false);
        } catch (const MqttError&) {
        }
        return;
    }
    changed_.notify_all();
}

void MqttBridge::answer() {
    for (;;) {
        std::string payload;
        {
            std::unique_lock lock(mutex_);
            changed_.wait(lock, [&] { return stopping_ || !commands_.empty(); });
            if (stopping_) return;
            payload = std::move(commands_.front());
            commands_.pop_front();
        }
        nlohmann::json reply{{"id", nullptr}};
        int status = 400;
        try {
            const nlohmann::json request = nlohmann::json::parse(payload);
            if (!request.is_object()) throw std::invalid_argument("a command is a JSON object");
            if (request.contains("id")) reply["id"] = request["id"];
            const nlohmann::json verb = request.value("verb", nlohmann::json());
            auto [code, body] = desk_ && verb == "resume_job" ? desk_->resume_job()
                                : desk_ && verb == "drop_job" ? desk_->drop_job()
                                                              : control_(request);
            status = code;
            for (auto& [k, v] : body.items()) reply[k] = v;
        } catch (const nlohmann::json::exception&) {
            reply["ok"] = false;
            reply["error"] = "a command is JSON: {\"id\": ..., \"verb\": ...}";
        } catch (const std::invalid_argument& e) {
            reply["ok"] = false;
            reply["error"] = e.what();
        }
        reply["status"] = status;
        try {
            client_->publish(topic("reply"), reply.dump(), 1, false);
        } catch (const MqttError&) {
        }
    }
}

}  // namespace pathstream::host::serve
