// `pathstream fleet`'s connection to the broker: the fleet's view kept up to date from the
// network thread, commands matched with their replies, and waits on both.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "pathstream/host/fleet_view.hpp"
#include "pathstream/host/mqtt_client.hpp"

namespace pathstream::host {

/// One watcher on the broker. It subscribes to the topics the view describes and to the
/// machines' replies, never to the queues (a job message carries a whole drawing: a watcher
/// does not need it). Thread-safe.
class FleetLink {
public:
    explicit FleetLink(MqttUrl url);
    ~FleetLink();
    FleetLink(const FleetLink&) = delete;
    FleetLink& operator=(const FleetLink&) = delete;

    /// Connects and subscribes; the broker sends the retained topics right after. Throws
    /// MqttError when the broker cannot be reached or refuses.
    void connect();
    /// Disconnects properly. Idempotent.
    void disconnect();

    /// Calls `read` with the view, under the lock (it must not block).
    void read(const std::function<void(const FleetView&)>& read) const;
    /// The view as JSON (FleetView::to_json).
    nlohmann::json view_json() const;
    /// Waits until `done(view)` holds (checked after every message) or `timeout` passes;
    /// returns whether it held. `done` runs under the lock.
    bool wait_for(const std::function<bool(const FleetView&)>& done,
                  std::chrono::milliseconds timeout) const;
    /// Publishes (MqttClient::publish).
    void publish(const std::string& topic, const std::string& payload, int qos, bool retain);

    /// Sends `request` (an object with a "verb") to machine `name` with a fresh id and waits
    /// for the reply with that id; nullopt after `timeout`. Throws MqttError when the broker
    /// does not take the command.
    std::optional<nlohmann::json> command(const std::string& name, nlohmann::json request,
                                          std::chrono::milliseconds timeout);

    const MqttUrl& url() const { return url_; }

private:
    void on_message(const std::string& topic, const std::string& payload);

    MqttUrl url_;
    std::unique_ptr<MqttClient> client_;
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;
    FleetView view_;
    std::map<std::string, std::optional<nlohmann::json>> replies_;  ///< by command id
    std::uint64_t next_command_ = 1;
    std::string prefix_;  ///< this watcher's command ids start with it
};

}  // namespace pathstream::host
