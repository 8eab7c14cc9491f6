#include "pathstream/hal/modbus_target.hpp"

#include <algorithm>
#include <charconv>
#include <iterator>
#include <set>
#include <stdexcept>

namespace pathstream::hal {
namespace {

constexpr std::string_view kTcpScheme = "modbus-tcp://";
constexpr std::string_view kRtuScheme = "modbus-rtu://";

[[noreturn]] void fail(std::string_view url, const std::string& what) {
    throw std::invalid_argument("bad target URL '" + std::string(url) + "': " + what);
}

// A whole decimal number in [lo, hi]; anything else (sign, spaces, hex, overflow) fails.
int parse_int(std::string_view url, std::string_view name, std::string_view text, int lo, int hi) {
    int value = 0;
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (text.empty() || ec != std::errc() || end != text.data() + text.size() || value < lo ||
        value > hi) {
        fail(url, std::string(name) + " '" + std::string(text) + "' is not a number in " +
                      std::to_string(lo) + ".." + std::to_string(hi));
    }
    return value;
}

// Applies "k=v&k=v" to the target. Each key at most once; keys the transport does not use
// are errors rather than silently ignored (a typo must not fall back to a default).
void parse_query(std::string_view url, std::string_view query, ModbusTarget& target) {
    const bool rtu = target.transport == ModbusTarget::Transport::kRtu;
    const std::string_view allowed = rtu ? "unit, baud, parity, data_bits, stop_bits" : "unit";
    std::set<std::string, std::less<>> seen;
    while (!query.empty()) {
        const std::size_t amp = query.find('&');
        const std::string_view item = query.substr(0, amp);
        query = amp == std::string_view::npos ? std::string_view{} : query.substr(amp + 1);
        if (item.empty()) fail(url, "empty query parameter");
        const std::size_t eq = item.find('=');
        if (eq == std::string_view::npos) {
            fail(url, "query parameter '" + std::string(item) + "' has no value (want name=value)");
        }
        const std::string_view key = item.substr(0, eq);
        const std::string_view value = item.substr(eq + 1);
        if (!seen.insert(std::string(key)).second) {
            fail(url, "parameter '" + std::string(key) + "' given twice");
        }
        if (key == "unit") {
            target.unit = parse_int(url, "unit", value, 0, rtu ? 247 : 255);
        } else if (rtu && key == "baud") {
            target.serial.baud = parse_int(url, "baud", value, 50, 4'000'000);
            // libmodbus maps the rate to a termios constant and silently uses 9600 for
            // anything else: refuse those here.
            static constexpr int kRates[] = {50,      75,      110,     134,     150,     200,
                                             300,     600,     1200,    1800,    2400,    4800,
                                             9600,    19200,   38400,   57600,   115200,  230400,
                                             460800,  500000,  576000,  921600,  1000000, 1152000,
                                             1500000, 2000000, 2500000, 3000000, 3500000, 4000000};
            if (std::find(std::begin(kRates), std::end(kRates), target.serial.baud) ==
                std::end(kRates)) {
                fail(url, "baud '" + std::string(value) +
                              "' is not a standard rate (e.g. 9600, 19200, 115200)");
            }
        } else if (rtu && key == "parity") {
            if (value.size() != 1 ||
                std::string_view("NEOneo").find(value[0]) == std::string_view::npos) {
                fail(url, "parity '" + std::string(value) + "' is not N, E or O");
            }
            target.serial.parity = static_cast<char>(value[0] & ~0x20);  // upper case
        } else if (rtu && key == "data_bits") {
            target.serial.data_bits = parse_int(url, "data_bits", value, 5, 8);
        } else if (rtu && key == "stop_bits") {
            target.serial.stop_bits = parse_int(url, "stop_bits", value, 1, 2);
        } else {
            fail(url, "unknown parameter '" + std::string(key) + "' (want " + std::string(allowed) +
                          ")");
        }
    }
}

void parse_tcp(std::string_view url, std::string_view rest, ModbusTarget& target) {
    const std::size_t slash = rest.find_first_of("/?");
    std::string_view authority = rest.substr(0, slash);
    std::string_view tail =
        slash == std::string_view::npos ? std::string_view{} : rest.substr(slash);
    if (!tail.empty() && tail[0] == '/') {
        const std::size_t q = tail.find('?');
        if (tail.substr(0, q) != "/")
            fail(url, "a TCP target has no path (got '" + std::string(tail.substr(0, q)) + "')");
        tail = tail.substr(q == std::string_view::npos ? tail.size() : q);
    }
    std::string_view port_text;
    if (!authority.empty() && authority[0] == '[') {  // [IPv6]:port
        const std::size_t close = authority.find(']');
        if (close == std::string_view::npos) fail(url, "unterminated '[' in host");
        target.host = std::string(authority.substr(1, close - 1));
        const std::string_view after = authority.substr(close + 1);
        if (!after.empty()) {
            if (after[0] != ':') fail(url, "expected ':PORT' after ']'");
            port_text = after.substr(1);
            if (port_text.empty()) fail(url, "empty port after ':'");
        }
    } else {
        const std::size_t colon = authority.rfind(':');
        target.host = std::string(authority.substr(0, colon));
        if (colon != std::string_view::npos) {
            port_text = authority.substr(colon + 1);
            if (port_text.empty()) fail(url, "empty port after ':'");
        }
    }
    if (target.host.empty()) fail(url, "missing host");
    if (!port_text.empty()) {
        target.port = static_cast<std::uint16_t>(parse_int(url, "port", port_text, 1, 65535));
    }
    if (!tail.empty()) parse_query(url, tail.substr(1), target);  // tail starts with '?'
}

void parse_rtu(std::string_view url, std::string_view rest, ModbusTarget& target) {
    const std::size_t q = rest.find('?');
    const std::string_view path = rest.substr(0, q);
    // modbus-rtu:///dev/ttyS0: the authority is empty, so what follows the scheme is the path.
    if (path.empty()) fail(url, "missing serial device path");
    if (path[0] != '/') {
        fail(url, "the serial device must be an absolute path (modbus-rtu:///dev/...), got '" +
                      std::string(path) + "'");
    }
    target.serial.device = std::string(path);
    if (q != std::string_view::npos) parse_query(url, rest.substr(q + 1), target);
}

}  // namespace

ModbusTarget parse_modbus_target(std::string_view url) {
    ModbusTarget target;
    if (url.starts_with(kTcpScheme)) {
        target.transport = ModbusTarget::Transport::kTcp;
        parse_tcp(url, url.substr(kTcpScheme.size()), target);
    } else if (url.starts_with(kRtuScheme)) {
        target.transport = ModbusTarget::Transport::kRtu;
        parse_rtu(url, url.substr(kRtuScheme.size()), target);
    } else {
        fail(url, "unknown scheme (want modbus-tcp:// or modbus-rtu://)");
    }
    return target;
}

std::string to_string(const ModbusTarget& target) {
    if (target.transport == ModbusTarget::Transport::kTcp) {
        const bool v6 = target.host.find(':') != std::string::npos;
        return std::string(kTcpScheme) + (v6 ? "[" + target.host + "]" : target.host) + ":" +
               std::to_string(target.port) + "?unit=" + std::to_string(target.unit);
    }
    const ModbusSerialLine& s = target.serial;
    return std::string(kRtuScheme) + s.device + "?baud=" + std::to_string(s.baud) +
           "&parity=" + s.parity + "&data_bits=" + std::to_string(s.data_bits) +
           "&stop_bits=" + std::to_string(s.stop_bits) + "&unit=" + std::to_string(target.unit);
}

}  // namespace pathstream::hal
