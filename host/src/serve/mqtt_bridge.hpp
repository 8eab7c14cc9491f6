// `serve --mqtt`: the machine's live events republished on an MQTT broker, and operator
// commands taken from its own command topic (docs/mqtt.md, "serve --mqtt").
#pragma once

#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <utility>

#include "event_hub.hpp"
#include "job_desk.hpp"
#include "pathstream/host/mqtt_client.hpp"

namespace pathstream::host::serve {

/// The broker and the machine's name on it (its topics are pathstream/NAME/...).
struct MqttLink {
    MqttUrl url;
    std::string name;
    std::string kind = "any";  ///< the queue it takes jobs from besides "any" (docs/mqtt.md)
};

/// Throws std::invalid_argument unless `name` is 1 to 64 of A-Z a-z 0-9 _ - (no MQTT
/// wildcard or level separator can enter a topic through it).
void check_machine_name(const std::string& name);

/// Runs a command ({"verb": ...}) as the HTTP API's /api/control does: status and body.
using ControlFunction = std::function<std::pair<int, nlohmann::json>(const nlohmann::json&)>;

/// Forwards `hub`'s events to the broker on its own thread and answers commands on another.
class MqttBridge {
public:
    /// `desk` (optional, outliving the bridge) takes jobs from the broker's queues.
    MqttBridge(MqttLink link, EventHub& hub, ControlFunction control, nlohmann::json identity,
               JobDesk* desk = nullptr);
    ~MqttBridge();
    MqttBridge(const MqttBridge&) = delete;
    MqttBridge& operator=(const MqttBridge&) = delete;

    /// Connects (with the last will "offline"), subscribes to the command topic, announces the
    /// machine online and starts forwarding. Throws MqttError when the broker cannot be
    /// reached, refuses, or refuses the subscription.
    void start();
    /// Announces the machine offline, stops the threads and disconnects. Idempotent.
    void stop();
    /// Publishes on the broker (after start()). Throws MqttError. Not on the network thread.
    void publish(const std::string& topic, const std::string& payload, int qos, bool retain);

private:
    void forward();
    void on_command(const std::string& payload);
    void answer();
    std::string topic(const std::string& leaf) const {
        return "pathstream/" + link_.name + "/" + leaf;
    }

    MqttLink link_;
    EventHub& hub_;
    ControlFunction control_;
    nlohmann::json identity_;
    JobDesk* desk_;
    std::unique_ptr<MqttClient> client_;
    std::thread forwarder_, worker_;
    std::mutex mutex_;
    std::condition_variable changed_;
    std::deque<std::string> commands_;  ///< waiting for the worker; at most kMaxQueued
    bool stopping_ = false;
};

}  // namespace pathstream::host::serve
