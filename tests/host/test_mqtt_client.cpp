// The MQTT client against a real broker (mosquitto on loopback, started by the test): publish
// and subscribe, retained state for a late subscriber, the last will on a dropped connection,
// passwords, and a shared subscription that hands each message to exactly one subscriber.
#include <catch2/catch.hpp>
#include <condition_variable>
#include <cstdio>
#include <fstream>
#include <map>
#include <mutex>
#include <set>

#include "mosquitto_broker.hpp"
#include "mqtt_inbox.hpp"
#include "pathstream/host/mqtt_client.hpp"

using namespace pathstream::host;
using pathstream::test::MosquittoBroker;

using Inbox = pathstream::test::MqttInbox;

TEST_CASE("mqtt: URLs", "[mqtt]") {
    const MqttUrl a = parse_mqtt_url("mqtt://broker.local");
    CHECK(!a.tls);
    CHECK(a.host == "broker.local");
    CHECK(a.port == 1883);
    const MqttUrl b = parse_mqtt_url("mqtts://ann:secret@10.0.0.2:9883?cafile=/etc/ca.pem");
    CHECK(b.tls);
    CHECK(b.port == 9883);
    CHECK(b.username == "ann");
    CHECK(b.password == "secret");
    CHECK(b.ca_file == "/etc/ca.pem");
    CHECK(b.text() == "mqtts://ann@10.0.0.2:9883");
    CHECK(parse_mqtt_url("mqtts://h").port == 8883);
    auto error_of = [](const std::string& url) {
        try {
            parse_mqtt_url(url);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of("http://h") == "mqtt URL \"http://h\": the scheme must be mqtt or mqtts");
    CHECK(error_of("mqtt://h:0") ==
          "mqtt URL \"mqtt://h:0\": the port must be a number from 1 to 65535");
    CHECK(error_of("mqtt://") == "mqtt URL \"mqtt://\": no host");
    CHECK(error_of("mqtt://h?cafile=x") == "mqtt URL \"mqtt://h?cafile=x\": cafile needs mqtts://");
    CHECK(error_of("mqtt://h?colour=red") ==
          "mqtt URL \"mqtt://h?colour=red\": unknown option \"colour\" (cafile, password_file)");
    CHECK(error_of("mqtt://ann@h?password_file=/nonexistent") ==
          "mqtt URL \"mqtt://ann@h?password_file=/nonexistent\": cannot read the password file "
          "/nonexistent");
}

TEST_CASE("mqtt: publish, subscribe and retained state", "[mqtt][threads]") {
    MosquittoBroker broker;
    Inbox inbox;
    MqttClient machine(parse_mqtt_url(broker.url()), "machine-1");
    machine.connect();
    machine.publish("pathstream/m1/state", "{\"state\":\"idle\"}", 1, true);
    // A subscriber that comes later gets the retained state at once.
    MqttClient watcher(parse_mqtt_url(broker.url()), "watcher", {}, inbox.sink());
    watcher.connect();
    watcher.subscribe("pathstream/+/state");
    REQUIRE(inbox.wait_for(1));
    machine.publish("pathstream/m1/state", "{\"state\":\"running\"}", 1, true);
    machine.publish("pathstream/m1/progress", "0.5", 0, false);  // not under the filter
    REQUIRE(inbox.wait_for(2));
    CHECK(inbox.messages[0] ==
          std::make_pair(std::string("pathstream/m1/state"), std::string("{\"state\":\"idle\"}")));
    CHECK(inbox.messages[1].second == "{\"state\":\"running\"}");
    machine.publish("pathstream/m2/state", "x", 1, false);
    REQUIRE(inbox.wait_for(3));
    CHECK(inbox.size() == 3);
}

TEST_CASE("mqtt: a dropped connection publishes the last will", "[mqtt][threads]") {
    MosquittoBroker broker;
    Inbox inbox;
    MqttClient watcher(parse_mqtt_url(broker.url()), "watcher", {}, inbox.sink());
    watcher.connect();
    watcher.subscribe("pathstream/m1/state");
    {
        MqttClient clean(parse_mqtt_url(broker.url()), "m1",
                         MqttClient::Will{"pathstream/m1/state", "offline", 1, true});
        clean.connect();
        clean.publish("pathstream/m1/state", "idle", 1, true);
        REQUIRE(inbox.wait_for(1));
        clean.disconnect();  // a proper goodbye: no will
    }
    MqttClient crashing(parse_mqtt_url(broker.url()), "m1",
                        MqttClient::Will{"pathstream/m1/state", "offline", 1, true});
    crashing.connect();
    crashing.publish("pathstream/m1/state", "running", 1, true);
    REQUIRE(inbox.wait_for(2));
    crashing.drop();
    REQUIRE(inbox.wait_for(3));
    CHECK(inbox.messages[0].second == "idle");
    CHECK(inbox.messages[1].second == "running");
    CHECK(inbox.messages[2].second == "offline");
}

TEST_CASE("mqtt: a broker with passwords refuses a client without one", "[mqtt]") {
    MosquittoBroker broker(std::map<std::string, std::string>{{"ann", "s3cret"}});
    MqttClient anonymous(parse_mqtt_url(broker.url()), "anon");
    try {
        anonymous.connect();
        FAIL("an anonymous client was let in");
    } catch (const MqttError& e) {
        CHECK(std::string(e.what()).find("refused the connection") != std::string::npos);
    }
    MqttClient wrong(parse_mqtt_url(broker.url("ann", "guess")), "wrong");
    CHECK_THROWS_AS(wrong.connect(), MqttError);
    MqttClient ann(parse_mqtt_url(broker.url("ann", "s3cret")), "ann");
    ann.connect();
    CHECK(ann.connected());
    ann.publish("pathstream/m1/state", "idle", 1, true);
}

TEST_CASE("mqtt: a shared subscription hands each job to exactly one machine", "[mqtt][threads]") {
    MosquittoBroker broker;
    std::vector<std::unique_ptr<Inbox>> inboxes;
    std::vector<std::unique_ptr<MqttClient>> machines;
    for (int m = 0; m < 3; ++m) {
        inboxes.push_back(std::make_unique<Inbox>());
        machines.push_back(std::make_unique<MqttClient>(parse_mqtt_url(broker.url()),
                                                        "machine-" + std::to_string(m),
                                                        std::nullopt, inboxes.back()->sink()));
        machines.back()->connect();
        machines.back()->subscribe("$share/plotters/pathstream/jobs");
    }
    MqttClient queue(parse_mqtt_url(broker.url()), "submitter");
    queue.connect();
    for (int j = 0; j < 20; ++j)
        queue.publish("pathstream/jobs", "job-" + std::to_string(j), 1, false);
    std::multiset<std::string> got;
    for (int round = 0; round < 200; ++round) {
        std::size_t total = 0;
        for (auto& inbox : inboxes) total += inbox->size();
        if (total >= 20) break;
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    std::size_t busy = 0;
    for (auto& inbox : inboxes) {
        std::lock_guard lock(inbox->mutex);
        for (const auto& m : inbox->messages) got.insert(m.second);
        busy += inbox->messages.empty() ? 0 : 1;
    }
    CHECK(got.size() == 20);
    for (int j = 0; j < 20; ++j) CHECK(got.count("job-" + std::to_string(j)) == 1);
    CHECK(busy >= 2);  // the broker spreads them: not everything to one machine
}

TEST_CASE("mqtt: a password file gives its first line, bounded", "[mqtt]") {
    const std::string file = "/tmp/pathstream_mqtt_pw_" + std::to_string(getpid());
    std::ofstream(file) << "s3cret\r\nsecond line\n";
    CHECK(parse_mqtt_url("mqtt://ann@h?password_file=" + file).password == "s3cret");
    std::ofstream(file) << std::string(5000, 'x');
    CHECK_THROWS_WITH(parse_mqtt_url("mqtt://ann@h?password_file=" + file),
                      Catch::Contains("first line is longer than 4096 bytes"));
    CHECK_THROWS_WITH(parse_mqtt_url("mqtt://ann@h?password_file=/dev/zero"),
                      Catch::Contains("first line is longer than 4096 bytes"));
    std::remove(file.c_str());
}
