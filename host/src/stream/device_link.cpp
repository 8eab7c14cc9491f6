// DeviceLink over Modbus and native CAN, opened from a target URL.
#include "pathstream/host/device_link.hpp"

#include <algorithm>
#include <stdexcept>

#include "can_link.hpp"
#include "modbus_link.hpp"
#include "pathstream/device/modbus_map.hpp"
#include "pathstream/hal/socketcan_bus.hpp"

namespace pathstream::host {

const char* command_verb(device::Command c) {
    switch (c) {
        case device::Command::kStart:
            return "start";
        case device::Command::kHold:
            return "hold";
        case device::Command::kResume:
            return "resume";
        case device::Command::kStop:
            return "stop";
        case device::Command::kReset:
            return "reset";
        case device::Command::kJog:
            return "jog";
        case device::Command::kSetPosition:
            return "position";
        case device::Command::kHome:
            return "home";
        case device::Command::kPen:
            return "pen";
    }
    return "unknown";
}

const char* axis_homing_name(device::AxisHoming h) {
    switch (h) {
        case device::AxisHoming::kNotHomed:
            return "not homed";
        case device::AxisHoming::kHoming:
            return "homing";
        case device::AxisHoming::kHomed:
            return "homed";
        case device::AxisHoming::kFailed:
            return "failed";
    }
    return "unknown";
}

const char* homing_error_name(device::HomingError e) {
    switch (e) {
        case device::HomingError::kNone:
            return "none";
        case device::HomingError::kBadConfig:
            return "a homing velocity or distance is out of range";
        case device::HomingError::kDeviceRefused:
            return "the device refused a homing step";
        case device::HomingError::kSwitchNotFound:
            return "switch not found within max_travel";
        case device::HomingError::kSwitchStuck:
            return "switch still active after moving off it";
        case device::HomingError::kLatchNotFound:
            return "the slow approach did not find the switch again";
        case device::HomingError::kInterrupted:
            return "interrupted by a fault, the e-stop or a stop";
    }
    return "unknown homing error";
}

namespace {

// Modbus: the status block and register 100; a refusal's reason is status register 30.
class ModbusDeviceLink final : public DeviceLink {
public:
    explicit ModbusDeviceLink(StreamOptions options)
        : options_(std::move(options)), link_(options_) {}

    DeviceSnapshot status() override {
        link_.mark_alive();
        return link_.read_status();
    }

    Status command(device::Command c) override {
        link_.mark_alive();
        try {
            link_.write_command(c);
            return Status::kOk;
        } catch (const hal::ModbusError& e) {
            const DeviceSnapshot s = link_.read_status();
            if (s.last_refusal != 0) return static_cast<Status>(s.last_refusal);
            link_.fail(std::string("command ") + command_verb(c) + ": " + e.what());
        }
    }

    Status command_with_arguments(std::uint8_t command, unsigned axis, std::int32_t value,
                                  std::uint16_t feed) override {
        link_.mark_alive();
        const auto v = static_cast<std::uint32_t>(value);
        const std::vector<std::uint16_t> r = {command, static_cast<std::uint16_t>(axis),
                                              static_cast<std::uint16_t>(v >> 16),
                                              static_cast<std::uint16_t>(v & 0xFFFFu), feed};
        try {
            link_.transact([&] { link_.client().write_registers(device::modbus::kCommand, r); });
            return Status::kOk;
        } catch (const hal::ModbusError& e) {
            const DeviceSnapshot s = link_.read_status();
            if (s.last_refusal != 0) return static_cast<Status>(s.last_refusal);
            link_.fail(std::string("command ") + std::to_string(command) + ": " + e.what());
        }
    }

    const std::string& name() const override { return options_.target; }

private:
    StreamOptions options_;
    ModbusLink link_;
};

// Native CAN: a status request (frames A to E) and the command frame with its ack.
class CanDeviceLink final : public DeviceLink {
public:
    CanDeviceLink(hal::CanBus& bus, const CanStreamOptions& options)
        : options_(options), link_(bus, options_, counters_) {}

    DeviceSnapshot status() override {
        link_.mark_alive();
        return snapshot_of(link_.request_status());
    }

    Status command(device::Command c) override {
        link_.mark_alive();
        const std::uint8_t r = link_.command(static_cast<std::uint8_t>(c));
        if (r >= pc::kResultIncomplete)
            link_.fail(std::string("command ") + command_verb(c) + ": " + can_result_name(r));
        return static_cast<Status>(r);
    }

    Status command_with_arguments(std::uint8_t command, unsigned axis, std::int32_t value,
                                  std::uint16_t feed) override {
        link_.mark_alive();
        pc::CommandArgs c;
        c.command = command;
        c.axis = static_cast<std::uint8_t>(axis);
        c.value = value;
        c.feed = feed;
        const std::uint8_t r =
            link_.command_frame(pc::encode_command_args(options_.node, c), command);
        if (r >= pc::kResultIncomplete) {
            link_.fail("command " + std::to_string(command) + ": " + can_result_name(r));
        }
        return static_cast<Status>(r);
    }

    const std::string& name() const override { return options_.name; }

private:
    CanStreamOptions options_;
    CanStreamReport counters_;
    CanLink link_;
};

// A CAN link that owns its SocketCAN socket.
class OwnedCanDeviceLink final : public DeviceLink {
public:
    OwnedCanDeviceLink(const std::string& interface_name, const CanStreamOptions& options)
        : bus_(interface_name), link_(bus_, options) {}
    DeviceSnapshot status() override { return link_.status(); }
    Status command(device::Command c) override { return link_.command(c); }
    Status command_with_arguments(std::uint8_t command, unsigned axis, std::int32_t value,
                                  std::uint16_t feed) override {
        return link_.command_with_arguments(command, axis, value, feed);
    }
    const std::string& name() const override { return link_.name(); }

private:
    hal::SocketCanBus bus_;
    CanDeviceLink link_;
};

}  // namespace

std::unique_ptr<DeviceLink> open_can_link(hal::CanBus& bus, const CanStreamOptions& options) {
    return std::make_unique<CanDeviceLink>(bus, options);
}

std::unique_ptr<DeviceLink> open_device_link(const std::string& target,
                                             const LinkOptions& options) {
    if (target.rfind("can://", 0) == 0) {
        const CanTarget t = parse_can_target(target);
        if (t.protocol != "native") {
            throw std::invalid_argument(target +
                                        ": ctl speaks the native CAN protocol, not CiA 402");
        }
        CanStreamOptions c;
        c.node = t.node;
        c.name = target;
        c.ack_timeout_ms = std::min(options.response_timeout_ms, 100u);
        c.link_timeout_seconds = options.link_timeout_seconds;
        return std::make_unique<OwnedCanDeviceLink>(t.interface_name, c);
    }
    if (target.rfind("modbus-tcp://", 0) != 0 && target.rfind("modbus-rtu://", 0) != 0) {
        throw std::invalid_argument(
            "bad target URL '" + target +
            "': unknown scheme (want modbus-tcp://, modbus-rtu:// or can://)");
    }
    StreamOptions m;
    m.target = target;
    m.response_timeout_ms = options.response_timeout_ms;
    m.attempts = options.attempts;
    m.link_timeout_seconds = options.link_timeout_seconds;
    return std::make_unique<ModbusDeviceLink>(m);
}

}  // namespace pathstream::host
