// can://IFACE?node=N&protocol=cia402&cycle=2ms
#include <cmath>
#include <stdexcept>
#include <string>

#include "pathstream/host/cia402_master.hpp"

namespace pathstream::host {
namespace {

unsigned long number(const std::string& text, const std::string& key, const std::string& url) {
    std::size_t used = 0;
    unsigned long v = 0;
    try {
        v = std::stoul(text, &used, 10);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size())
        throw std::invalid_argument(url + ": " + key + " wants a number, not '" + text + "'");
    return v;
}

double positive_number(const std::string& text, const std::string& key, const std::string& url) {
    std::size_t used = 0;
    double v = 0;
    try {
        v = std::stod(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v) || v <= 0)
        throw std::invalid_argument(url + ": " + key + " wants a number > 0, not '" + text + "'");
    return v;
}

std::uint32_t milliseconds(std::string text, const std::string& key, const std::string& url) {
    if (text.size() > 2 && text.compare(text.size() - 2, 2, "ms") == 0)
        text.resize(text.size() - 2);
    return static_cast<std::uint32_t>(number(text, key, url));
}

std::uint8_t node_id(const std::string& text, const std::string& url) {
    const unsigned long n = number(text, "node", url);
    if (n < 1 || n > 127) throw std::invalid_argument(url + ": node " + text + " outside 1..127");
    return static_cast<std::uint8_t>(n);
}

}  // namespace

Cia402Target parse_cia402_target(const std::string& url, std::size_t axes) {
    const std::string scheme = "can://";
    if (url.compare(0, scheme.size(), scheme) != 0)
        throw std::invalid_argument(url + ": a CAN target starts with can://");
    const std::size_t q = url.find('?', scheme.size());
    Cia402Target t;
    t.interface =
        url.substr(scheme.size(), q == std::string::npos ? std::string::npos : q - scheme.size());
    if (t.interface.empty())
        throw std::invalid_argument(url + ": no CAN interface (can://can0?...)");
    bool cia402 = false;
    t.options.nodes.clear();
    std::string query = q == std::string::npos ? "" : url.substr(q + 1);
    while (!query.empty()) {
        const std::size_t amp = query.find('&');
        const std::string item = query.substr(0, amp);
        query = amp == std::string::npos ? "" : query.substr(amp + 1);
        const std::size_t eq = item.find('=');
        if (eq == std::string::npos)
            throw std::invalid_argument(url + ": '" + item + "' is not KEY=VALUE");
        const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
        if (key == "protocol") {
            if (value != "cia402")
                throw std::invalid_argument(url + ": protocol '" + value + "' is not cia402");
            cia402 = true;
        } else if (key == "node") {
            const std::uint8_t first = node_id(value, url);
            if (first + axes - 1 > 127)
                throw std::invalid_argument(url + ": nodes " + value + ".. run past 127");
            for (std::size_t a = 0; a < axes; ++a)
                t.options.nodes.push_back(static_cast<std::uint8_t>(first + a));
        } else if (key == "nodes") {
            std::string list = value;
            while (!list.empty()) {
                const std::size_t comma = list.find(',');
                t.options.nodes.push_back(node_id(list.substr(0, comma), url));
                list = comma == std::string::npos ? "" : list.substr(comma + 1);
            }
        } else if (key == "cycle") {
            t.options.cycle_ms = milliseconds(value, key, url);
            if (t.options.cycle_ms < 1 || t.options.cycle_ms > 255)
                throw std::invalid_argument(url + ": cycle 1..255 ms");
        } else if (key == "heartbeat") {
            const std::uint32_t hb = milliseconds(value, key, url);
            if (hb > 10000) throw std::invalid_argument(url + ": heartbeat at most 10000 ms");
            t.options.heartbeat_ms = static_cast<std::uint16_t>(hb);
            t.options.heartbeat_timeout_ms = hb * 3 + 50;
        } else if (key == "echo") {
            t.options.demand_echo = value == "1" || value == "true";
        } else if (key == "ff") {
            if (value == "none") {
                t.options.feed_forward = Cia402FeedForward::kNone;
            } else if (value == "velocity") {
                t.options.feed_forward = Cia402FeedForward::kVelocity;
            } else if (value == "torque") {
                t.options.feed_forward = Cia402FeedForward::kTorque;
            } else {
                throw std::invalid_argument(url + ": ff '" + value +
                                            "' is not none, velocity or torque");
            }
        } else if (key == "inertia") {
            t.options.torque_per_acceleration = positive_number(value, key, url);
        } else {
            throw std::invalid_argument(
                url + ": unknown key '" + key +
                "' (node, nodes, protocol, cycle, heartbeat, echo, ff, inertia)");
        }
    }
    if (!cia402) throw std::invalid_argument(url + ": protocol=cia402 missing");
    if (t.options.nodes.empty()) {
        for (std::size_t a = 0; a < axes; ++a)
            t.options.nodes.push_back(static_cast<std::uint8_t>(1 + a));
    }
    if (t.options.feed_forward == Cia402FeedForward::kTorque &&
        t.options.torque_per_acceleration == 0) {
        throw std::invalid_argument(url +
                                    ": ff=torque needs inertia=X (per mille of rated torque per "
                                    "LSB/s^2)");
    }
    if (t.options.nodes.size() != axes) {
        throw std::invalid_argument(url + ": " + std::to_string(t.options.nodes.size()) +
                                    " nodes for " + std::to_string(axes) + " axes");
    }
    return t;
}

}  // namespace pathstream::host
