// `stream --mqtt`: a headless machine on the broker. The stream's own events go to the
// machine's topics as serve publishes them, and operator commands on its command topic run
// through `ctl` (docs/mqtt.md, "stream --mqtt").
#pragma once

#include <memory>
#include <string>

#include "event_hub.hpp"
#include "mqtt_bridge.hpp"
#include "operator_command.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host::serve {

/// The bridge of one streaming command. Not copyable; stop() (or the destructor) announces
/// the machine offline.
class StreamReporter {
public:
    /// `link`: broker and name (its kind unused: a stream takes no jobs).
    StreamReporter(MqttLink link, MachineProfile machine, OperatorTarget target,
                   const std::string& machine_file);
    ~StreamReporter();
    StreamReporter(const StreamReporter&) = delete;
    StreamReporter& operator=(const StreamReporter&) = delete;

    /// Connects and announces the machine online. Throws MqttError when the broker cannot be
    /// reached or refuses. Init, before the job starts.
    void start();
    /// One event's line (EventChannel::tap): published on the machine's topics. Any thread.
    void event(const std::string& line);
    /// Announces the machine offline and disconnects. Idempotent.
    void stop();

private:
    MachineProfile machine_;
    OperatorTarget target_;
    EventHub hub_;
    std::unique_ptr<MqttBridge> bridge_;
};

}  // namespace pathstream::host::serve
