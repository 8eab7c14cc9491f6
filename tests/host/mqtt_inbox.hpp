// The messages an MQTT client of a test received, waited for with a bound (never a
// measurement): shared by the client's and serve's broker tests.
#pragma once

#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "pathstream/host/mqtt_client.hpp"

namespace pathstream::test {

struct MqttInbox {
    using Messages = std::vector<std::pair<std::string, std::string>>;
    std::mutex mutex;
    std::condition_variable changed;
    Messages messages;  ///< topic and payload, in arrival order

    /// The client's on_message: appends (from the network thread).
    host::MqttClient::OnMessage sink() {
        return [this](const std::string& topic, const std::string& payload) {
            {
                std::lock_guard lock(mutex);
                messages.emplace_back(topic, payload);
            }
            changed.notify_all();
        };
    }
    /// Waits at most 20 s until `pred(messages)` holds; false if it never did.
    template <class Pred>
    bool wait(Pred pred) {
        std::unique_lock lock(mutex);
        return changed.wait_for(lock, std::chrono::seconds(20), [&] { return pred(messages); });
    }
    /// Waits until `n` messages are here.
    bool wait_for(std::size_t n) {
        return wait([n](const Messages& m) { return m.size() >= n; });
    }
    std::size_t size() {
        std::lock_guard lock(mutex);
        return messages.size();
    }
};

}  // namespace pathstream::test
