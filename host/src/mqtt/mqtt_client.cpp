// libmosquitto behind a blocking interface: its network thread runs the callbacks, which
// record acknowledgements by message id; the calling thread waits for its own.
#include "pathstream/host/mqtt_client.hpp"

#include <mosquitto.h>
#include <mqtt_protocol.h>

#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <set>
#include <vector>

namespace pathstream::host {
namespace {

// libmosquitto keeps global state (its TLS library) that must be set up once per process.
void init_library_once() {
    static const int done = [] { return mosquitto_lib_init(); }();
    (void)done;
}

}  // namespace

struct MqttClient::State {
    MqttUrl url;
    std::string id;
    std::optional<Will> will;
    OnMessage on_message;
    std::uint32_t session_expiry_s = 0;
    mosquitto* mosq = nullptr;
    bool loop_running = false;

    std::mutex mutex;
    std::condition_variable changed;
    bool connected = false;
    std::optional<int> connect_result;  // the broker's reason code for the last CONNECT
    std::string last_error;             // libmosquitto's last error log line (a TLS failure)
    std::set<int> acked;                // message ids acknowledged (PUBACK, SUBACK, UNSUBACK)
    std::vector<int> refused;           // SUBACK with a failure code, by message id
    std::vector<std::pair<std::string, int>> subscriptions;  // renewed after a reconnect
    std::atomic<std::uint64_t> received{0};

    template <class Pred>
    bool wait(std::unique_lock<std::mutex>& lock, std::chrono::milliseconds timeout, Pred pred) {
        return changed.wait_for(lock, timeout, pred);
    }
};

MqttClient::MqttClient(MqttUrl url, std::string client_id, std::optional<Will> will,
                       OnMessage on_message, std::uint32_t session_expiry_s)
    : state_(std::make_unique<State>()) {
    init_library_once();
    State& s = *state_;
    s.url = std::move(url);
    s.id = std::move(client_id);
    s.will = std::move(will);
    s.on_message = std::move(on_message);
    s.session_expiry_s = session_expiry_s;
    s.mosq = mosquitto_new(s.id.c_str(), session_expiry_s == 0, &s);
    if (!s.mosq) throw MqttError("cannot create an MQTT client (out of memory?)");
    mosquitto_int_option(s.mosq, MOSQ_OPT_PROTOCOL_VERSION, MQTT_PROTOCOL_V5);
    // A TLS handshake that fails ends the connection without a CONNACK: what went wrong is only
    // in libmosquitto's log, kept for the error message.
    mosquitto_log_callback_set(s.mosq, [](mosquitto*, void* obj, int level, const char* text) {
        if (level != MOSQ_LOG_ERR || text == nullptr) return;
        auto& st = *static_cast<State*>(obj);
        std::lock_guard lock(st.mutex);
        st.last_error = std::string(text).substr(0, 300);
    });
    mosquitto_connect_v5_callback_set(
        s.mosq, [](mosquitto* m, void* obj, int rc, int, const mosquitto_property*) {
            auto& st = *static_cast<State*>(obj);
            std::vector<std::pair<std::string, int>> renew;
            {
                std::lock_guard lock(st.mutex);
                st.connect_result = rc;
                st.connected = rc == 0;
                if (rc == 0) renew = st.subscriptions;
            }
            // A clean session forgets subscriptions: after a reconnect, ask again.
            for (const auto& [filter, qos] : renew) {
                mosquitto_subscribe_v5(m, nullptr, filter.c_str(), qos, 0, nullptr);
            }
            st.changed.notify_all();
        });
    mosquitto_disconnect_v5_callback_set(s.mosq,
                                         [](mosquitto*, void* obj, int, const mosquitto_property*) {
                                             auto& st = *static_cast<State*>(obj);
                                             {
                                                 std::lock_guard lock(st.mutex);
                                                 st.connected = false;
                                             }
                                             st.changed.notify_all();
                                         });
    mosquitto_publish_v5_callback_set(
        s.mosq, [](mosquitto*, void* obj, int mid, int, const mosquitto_property*) {
            auto& st = *static_cast<State*>(obj);
            {
                std::lock_guard lock(st.mutex);
                st.acked.insert(mid);
            }
            st.changed.notify_all();
        });
    mosquitto_subscribe_v5_callback_set(s.mosq, [](mosquitto*, void* obj, int mid, int count,
                                                   const int* granted, const mosquitto_property*) {
        auto& st = *static_cast<State*>(obj);
        {
            std::lock_guard lock(st.mutex);
            for (int i = 0; i < count; ++i) {
                if (granted[i] >= 0x80) st.refused.push_back(mid);
            }
            st.acked.insert(mid);
        }
        st.changed.notify_all();
    });
    mosquitto_unsubscribe_v5_callback_set(
        s.mosq, [](mosquitto*, void* obj, int mid, const mosquitto_property*) {
            auto& st = *static_cast<State*>(obj);
            {
                std::lock_guard lock(st.mutex);
                st.acked.insert(mid);
            }
            st.changed.notify_all();
        });
    mosquitto_message_v5_callback_set(
        s.mosq, [](mosquitto*, void* obj, const mosquitto_message* m, const mosquitto_property*) {
            auto& st = *static_cast<State*>(obj);
            ++st.received;
            if (st.on_message) {
                st.on_message(m->topic, std::string(static_cast<const char*>(m->payload),
                                                    static_cast<std::size_t>(m->payloadlen)));
            }
        });
}

MqttClient::~MqttClient() {
    if (!state_ || !state_->mosq) return;
    disconnect();
    mosquitto_destroy(state_->mosq);
}

void MqttClient::connect(std::chrono::milliseconds timeout, int keepalive_s) {
    State& s = *state_;
    if (!s.url.username.empty()) {
        mosquitto_username_pw_set(s.mosq, s.url.username.c_str(),
                                  s.url.password.empty() ? nullptr : s.url.password.c_str());
    }
    if (s.url.tls) {
        const int rc =
            s.url.ca_file.empty()
                ? mosquitto_tls_set(s.mosq, nullptr, "/etc/ssl/certs", nullptr, nullptr, nullptr)
                : mosquitto_tls_set(s.mosq, s.url.ca_file.c_str(), nullptr, nullptr, nullptr,
                                    nullptr);
        if (rc != MOSQ_ERR_SUCCESS)
            throw MqttError("TLS setup for " + s.url.text() + ": " + mosquitto_strerror(rc));
    }
    if (s.will) {
        const int rc = mosquitto_will_set_v5(
            s.mosq, s.will->topic.c_str(), static_cast<int>(s.will->payload.size()),
            s.will->payload.data(), s.will->qos, s.will->retain, nullptr);
        if (rc != MOSQ_ERR_SUCCESS)
            throw MqttError(std::string("the last will: ") + mosquitto_strerror(rc));
    }
    {
        std::lock_guard lock(s.mutex);
        s.connect_result.reset();
    }
    mosquitto_property* properties = nullptr;
    if (s.session_expiry_s != 0)
        mosquitto_property_add_int32(&properties, MQTT_PROP_SESSION_EXPIRY_INTERVAL,
                                     s.session_expiry_s);
    int rc = mosquitto_connect_bind_v5(s.mosq, s.url.host.c_str(), s.url.port, keepalive_s, nullptr,
                                       properties);
    mosquitto_property_free_all(&properties);
    if (rc != MOSQ_ERR_SUCCESS) {
        const std::string reason =
            rc == MOSQ_ERR_ERRNO ? std::string(std::strerror(errno)) : mosquitto_strerror(rc);
        std::string detail;
        {
            std::lock_guard lock(s.mutex);
            detail = s.last_error;
        }
        throw MqttError("cannot reach the broker " + s.url.text() + ": " + reason +
                        (detail.empty() ? "" : " (" + detail + ")"));
    }
    if (!s.loop_running) {
        rc = mosquitto_loop_start(s.mosq);
        if (rc != MOSQ_ERR_SUCCESS)
            throw MqttError(std::string("the MQTT thread: ") + mosquitto_strerror(rc));
        s.loop_running = true;
    }
    std::string failure;
    {
        std::unique_lock lock(s.mutex);
        if (!s.wait(lock, timeout, [&] { return s.connect_result.has_value(); })) {
            failure = "no answer from the broker " + s.url.text() + " within " +
                      std::to_string(timeout.count()) + " ms" +
                      (s.last_error.empty() ? "" : " (" + s.last_error + ")");
        } else if (*s.connect_result != 0) {
            failure = "the broker " + s.url.text() +
                      " refused the connection: " + mosquitto_reason_string(*s.connect_result);
        }
    }
    if (!failure.empty()) {
        // The network thread would otherwise keep trying to reconnect.
        disconnect();
        throw MqttError(failure);
    }
}

void MqttClient::publish(const std::string& topic, const std::string& payload, int qos, bool retain,
                         std::chrono::milliseconds timeout) {
    State& s = *state_;
    int mid = 0;
    const int rc =
        mosquitto_publish_v5(s.mosq, &mid, topic.c_str(), static_cast<int>(payload.size()),
                             payload.data(), qos, retain, nullptr);
    if (rc != MOSQ_ERR_SUCCESS)
        throw MqttError("publish on " + topic + ": " + mosquitto_strerror(rc));
    if (qos == 0) return;
    std::unique_lock lock(s.mutex);
    if (!s.wait(lock, timeout, [&] { return s.acked.count(mid) != 0 || !s.connected; }) ||
        s.acked.count(mid) == 0) {
        throw MqttError("publish on " + topic + ": the broker did not acknowledge it");
    }
    s.acked.erase(mid);
}

void MqttClient::subscribe(const std::string& filter, int qos, std::chrono::milliseconds timeout) {
    State& s = *state_;
    int mid = 0;
    const int rc = mosquitto_subscribe_v5(s.mosq, &mid, filter.c_str(), qos, 0, nullptr);
    if (rc != MOSQ_ERR_SUCCESS)
        throw MqttError("subscribe to " + filter + ": " + mosquitto_strerror(rc));
    std::unique_lock lock(s.mutex);
    if (!s.wait(lock, timeout, [&] { return s.acked.count(mid) != 0; })) {
        throw MqttError("subscribe to " + filter + ": no answer from the broker");
    }
    s.acked.erase(mid);
    if (std::erase(s.refused, mid) != 0)
        throw MqttError("the broker refused the subscription to " + filter);
    s.subscriptions.emplace_back(filter, qos);
}

void MqttClient::unsubscribe(const std::string& filter, std::chrono::milliseconds timeout) {
    State& s = *state_;
    int mid = 0;
    const int rc = mosquitto_unsubscribe_v5(s.mosq, &mid, filter.c_str(), nullptr);
    if (rc != MOSQ_ERR_SUCCESS)
        throw MqttError("unsubscribe from " + filter + ": " + mosquitto_strerror(rc));
    std::unique_lock lock(s.mutex);
    std::erase_if(s.subscriptions, [&](const auto& f) { return f.first == filter; });
    if (!s.wait(lock, timeout, [&] { return s.acked.count(mid) != 0; })) {
        throw MqttError("unsubscribe from " + filter + ": no answer from the broker");
    }
    s.acked.erase(mid);
}

void MqttClient::disconnect() {
    State& s = *state_;
    if (!s.mosq) return;
    // A proper disconnect ends a kept session too: nothing more is queued for this client.
    mosquitto_property* properties = nullptr;
    if (s.session_expiry_s != 0)
        mosquitto_property_add_int32(&properties, MQTT_PROP_SESSION_EXPIRY_INTERVAL, 0);
    mosquitto_disconnect_v5(s.mosq, MQTT_RC_NORMAL_DISCONNECTION, properties);
    mosquitto_property_free_all(&properties);
    if (s.loop_running) {
        mosquitto_loop_stop(s.mosq, false);
        s.loop_running = false;
    }
}

void MqttClient::drop() {
    State& s = *state_;
    if (!s.mosq) return;
    // Destroying the client closes its socket without a DISCONNECT: to the broker, a crash.
    if (s.loop_running) {
        mosquitto_loop_stop(s.mosq, true);
        s.loop_running = false;
    }
    mosquitto_destroy(s.mosq);
    s.mosq = nullptr;
    std::lock_guard lock(s.mutex);
    s.connected = false;
}

bool MqttClient::connected() const {
    std::lock_guard lock(state_->mutex);
    return state_->connected;
}

std::uint64_t MqttClient::received() const {
    return state_->received;
}

}  // namespace pathstream::host
