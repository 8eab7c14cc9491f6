// The target URL parsers (Modbus, native CAN, CiA 402, MQTT brokers): a target, or
// std::invalid_argument;
// a parsed Modbus target's canonical URL parses back to the same target.
#include <stdexcept>

#include "fuzz_support.hpp"
#include "pathstream/hal/modbus_target.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/cia402_master.hpp"
#include "pathstream/host/mqtt_client.hpp"

namespace {

// Anything but std::invalid_argument escaping a parser is a bug.
template <typename Parse>
void refused_only_as_invalid(Parse&& parse) {
    try {
        parse();
    } catch (const std::invalid_argument&) {
    } catch (const std::exception& e) {
        pathstream::fuzz::violated(std::string("not invalid_argument: ") + e.what());
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    if (size < 1) return 0;
    const std::size_t axes = 1 + data[0] % 8u;
    const std::string url = fuzz::text_of(data + 1, size - 1);
    refused_only_as_invalid([&] {
        const hal::ModbusTarget t = hal::parse_modbus_target(url);
        const std::string canonical = hal::to_string(t);
        const hal::ModbusTarget back = hal::parse_modbus_target(canonical);
        if (hal::to_string(back) != canonical)
            fuzz::violated("canonical URL does not round-trip: " + canonical);
    });
    refused_only_as_invalid([&] {
        const host::CanTarget t = host::parse_can_target(url);
        if (t.node < 1 || t.node > 127) fuzz::violated("CAN node out of range");
    });
    refused_only_as_invalid([&] { (void)host::parse_cia402_target(url, axes); });
    refused_only_as_invalid([&] {
        const host::MqttUrl t = host::parse_mqtt_url(url);
        if (t.host.empty() || t.port < 1 || t.port > 65535) fuzz::violated("MQTT host or port");
        if (t.password.size() > 4096 + url.size()) fuzz::violated("an unbounded password");
    });
    return 0;
}
