// serve's MQTT bridge with two real threads against a real broker (mosquitto on loopback): the
// hub's events forwarded in order while commands are answered, each once, with its id; a
// queue that is full answers 503 at once; the retained status is the latest.
#include <atomic>
#include <catch2/catch.hpp>
#include <condition_variable>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "../host/mosquitto_broker.hpp"
#include "../host/mqtt_inbox.hpp"
#include "serve/mqtt_bridge.hpp"

using namespace pathstream::host;
using namespace pathstream::host::serve;
using Json = nlohmann::json;

namespace {

using Inbox = pathstream::test::MqttInbox;

std::size_t count_on(const std::vector<std::pair<std::string, std::string>>& m,
                     const std::string& topic) {
    return static_cast<std::size_t>(
        std::count_if(m.begin(), m.end(), [&](const auto& x) { return x.first == topic; }));
}

}  // namespace

TEST_CASE("mqtt bridge: events forwarded in order while commands are answered", "[mqtt][threads]") {
    pathstream::test::MosquittoBroker broker;
    EventHub hub;
    std::atomic<int> controls{0};
    MqttBridge bridge(
        MqttLink{parse_mqtt_url(broker.url()), "m1"}, hub,
        [&](const Json& request) {
            ++controls;
            return std::make_pair(200, Json{{"ok", true}, {"verb", request.value("verb", "")}});
        },
        Json{{"name", "m1"}});
    Inbox inbox;
    MqttClient watcher(parse_mqtt_url(broker.url()), "watcher", {}, inbox.sink());
    watcher.connect();
    watcher.subscribe("pathstream/m1/#");
    bridge.start();
    REQUIRE(inbox.wait([](const auto& m) { return count_on(m, "pathstream/m1/online") >= 1; }));
    // The hub is fed from one thread while commands come in through the broker.
    std::thread feeder([&] {
        for (int i = 0; i < 200; ++i) {
            hub.publish(Json{{"event", "device"}, {"n", i}}.dump(), "device");
        }
    });
    MqttClient operator_(parse_mqtt_url(broker.url()), "operator");
    operator_.connect();
    for (int c = 0; c < 6; ++c) {
        operator_.publish("pathstream/m1/command", Json{{"id", c}, {"verb", "hold"}}.dump(), 1,
                          false);
    }
    feeder.join();
    REQUIRE(inbox.wait([](const auto& m) {
        return count_on(m, "pathstream/m1/reply") >= 6 &&
               count_on(m, "pathstream/m1/events") >= 200;
    }));
    bridge.stop();
    std::lock_guard lock(inbox.mutex);
    int next = 0;
    std::vector<int> ids;
    for (const auto& [topic, payload] : inbox.messages) {
        const Json j = Json::parse(payload);
        if (topic == "pathstream/m1/events") {
            CHECK(j["n"] == next);  // every event, in order
            ++next;
        } else if (topic == "pathstream/m1/reply") {
            CHECK(j["status"] == 200);
            CHECK(j["ok"] == true);
            ids.push_back(j["id"].get<int>());
        }
    }
    CHECK(next == 200);
    CHECK(ids == std::vector<int>{0, 1, 2, 3, 4, 5});  // each once, in order
    CHECK(controls.load() == 6);
}

TEST_CASE("mqtt bridge: a full command queue answers 503 at once", "[mqtt][threads]") {
    pathstream::test::MosquittoBroker broker;
    EventHub hub;
    std::mutex gate;
    gate.lock();  // the first command holds the worker until the test lets it go
    std::atomic<bool> entered{false};
    MqttBridge bridge(
        MqttLink{parse_mqtt_url(broker.url()), "m2"}, hub,
        [&](const Json&) {
            entered = true;
            std::lock_guard hold(gate);
            return std::make_pair(200, Json{{"ok", true}});
        },
        Json{{"name", "m2"}});
    Inbox inbox;
    MqttClient watcher(parse_mqtt_url(broker.url()), "watcher", {}, inbox.sink());
    watcher.connect();
    watcher.subscribe("pathstream/m2/reply");
    bridge.start();
    MqttClient operator_(parse_mqtt_url(broker.url()), "operator");
    operator_.connect();
    // One runs (held), then eight wait and the rest are refused: 12 sent.
    operator_.publish("pathstream/m2/command", Json{{"id", 0}, {"verb", "hold"}}.dump(), 1, false);
    for (int i = 0; i < 2000 && !entered; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    REQUIRE(entered);
    for (int c = 1; c < 12; ++c) {
        operator_.publish("pathstream/m2/command", Json{{"id", c}, {"verb", "hold"}}.dump(), 1,
                          false);
    }
    REQUIRE(inbox.wait([](const auto& m) { return m.size() >= 3; }));
    gate.unlock();
    REQUIRE(inbox.wait([](const auto& m) { return m.size() >= 12; }));
    bridge.stop();
    std::lock_guard lock(inbox.mutex);
    int busy = 0, done = 0;
    for (const auto& [topic, payload] : inbox.messages) {
        const Json j = Json::parse(payload);
        if (j["status"] == 503) {
            ++busy;
            CHECK(j["error"] == "busy: 8 commands are waiting already");
            CHECK(j["id"].get<int>() >= 9);
        } else {
            ++done;
        }
    }
    CHECK(busy == 3);
    CHECK(done == 9);
}
