// An MQTT 5 client on Debian's libmosquitto: what a machine needs to report to a broker and
// take commands and jobs from it (docs/mqtt.md).
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

namespace pathstream::host {

/// Where the broker is and how to log in: mqtt://[USER[:PASSWORD]@]HOST[:PORT] (port 1883) or
/// mqtts://... (TLS, port 8883), optionally ?cafile=PATH (the CA that signed the broker's
/// certificate; default: the system's) and &password_file=PATH (the password read from the
/// file's first line, so that it is not on the command line).
struct MqttUrl {
    bool tls = false;
    std::string host;
    int port = 1883;
    std::string username;
    std::string password;
    std::string ca_file;

    /// The URL again, the password left out ("mqtt://ann@broker:1883"): for logs.
    std::string text() const;
};

/// Parses `url`. Throws std::invalid_argument naming what is wrong ("mqtt URL
/// \"http://x\": the scheme must be mqtt or mqtts"). Reads the password file when one is named
/// (std::invalid_argument when it cannot be read).
MqttUrl parse_mqtt_url(const std::string& url);

/// A failure of the broker or the connection; what() says which and why ("the broker refused
/// the connection: not authorized").
class MqttError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// One connection to a broker. Messages arrive on libmosquitto's network thread: `on_message`
/// runs there and must not block long. Publishing and subscribing may be called from any thread
/// once connected. Not copyable.
class MqttClient {
public:
    /// A message the broker publishes for this client when the connection ends without a
    /// proper disconnect (a crash, a cut network): its last will.
    struct Will {
        std::string topic;
        std::string payload;
        int qos = 1;
        bool retain = true;
    };
    using OnMessage = std::function<void(const std::string& topic, const std::string& payload)>;

    /// Creates the client (no connection yet). `client_id` must be unique on the broker.
    /// `session_expiry_s` 0: a clean session, forgotten at disconnect. Otherwise the broker
    /// keeps the session (its subscriptions and the QoS 1 messages for it) that long after the
    /// connection ends, and a client with the same id resumes it.
    MqttClient(MqttUrl url, std::string client_id, std::optional<Will> will = {},
               OnMessage on_message = {}, std::uint32_t session_expiry_s = 0);
    ~MqttClient();
    MqttClient(const MqttClient&) = delete;
    MqttClient& operator=(const MqttClient&) = delete;

    /// Connects and waits for the broker's answer. Throws MqttError when the broker cannot be
    /// reached or refuses (with its reason), or after `timeout`. Keep-alive: `keepalive_s`.
    void connect(std::chrono::milliseconds timeout = std::chrono::seconds(5), int keepalive_s = 10);

    /// Publishes `payload` on `topic`; with qos >= 1, waits until the broker has it. Throws
    /// MqttError when not connected or after `timeout`.
    void publish(const std::string& topic, const std::string& payload, int qos = 1,
                 bool retain = false, std::chrono::milliseconds timeout = std::chrono::seconds(5));

    /// Subscribes to `filter` ("pathstream/+/state", "$share/group/topic") and waits for the
    /// broker's grant. Throws MqttError when the broker refuses or after `timeout`.
    void subscribe(const std::string& filter, int qos = 1,
                   std::chrono::milliseconds timeout = std::chrono::seconds(5));
    void unsubscribe(const std::string& filter,
                     std::chrono::milliseconds timeout = std::chrono::seconds(5));

    /// Ends the connection properly: the broker drops the will and ends a kept session.
    void disconnect();
    /// Ends the connection without telling the broker, as a crash would: the broker then
    /// publishes the will. For tests and for a machine that must appear dead.
    void drop();

    bool connected() const;
    /// Messages received so far (from the network thread).
    std::uint64_t received() const;

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace pathstream::host
