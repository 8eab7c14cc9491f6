// MQTT broker URLs: scheme, credentials, host, port and the TLS and password-file options.
#include <charconv>
#include <fstream>

#include "pathstream/host/mqtt_client.hpp"

namespace pathstream::host {
namespace {

[[noreturn]] void bad(const std::string& url, const std::string& why) {
    throw std::invalid_argument("mqtt URL \"" + url + "\": " + why);
}

}  // namespace

std::string MqttUrl::text() const {
    return std::string(tls ? "mqtts://" : "mqtt://") + (username.empty() ? "" : username + "@") +
           host + ":" + std::to_string(port);
}

MqttUrl parse_mqtt_url(const std::string& url) {
    MqttUrl u;
    std::string rest;
    if (url.rfind("mqtt://", 0) == 0) {
        rest = url.substr(7);
    } else if (url.rfind("mqtts://", 0) == 0) {
        u.tls = true;
        u.port = 8883;
        rest = url.substr(8);
    } else {
        bad(url, "the scheme must be mqtt or mqtts");
    }
    std::string query;
    if (const auto q = rest.find('?'); q != std::string::npos) {
        query = rest.substr(q + 1);
        rest.resize(q);
    }
    if (const auto at = rest.rfind('@'); at != std::string::npos) {
        const std::string user = rest.substr(0, at);
        rest = rest.substr(at + 1);
        const auto colon = user.find(':');
        u.username = user.substr(0, colon);
        if (colon != std::string::npos) u.password = user.substr(colon + 1);
        if (u.username.empty()) bad(url, "a user name must come before '@'");
    }
    if (!rest.empty() && rest.back() == '/') rest.pop_back();
    const auto colon = rest.rfind(':');
    u.host = rest.substr(0, colon);
    if (colon != std::string::npos) {
        const std::string port = rest.substr(colon + 1);
        int p = 0;
        const auto [end, ec] = std::from_chars(port.data(), port.data() + port.size(), p);
        if (ec != std::errc() || end != port.data() + port.size() || p < 1 || p > 65535) {
            bad(url, "the port must be a number from 1 to 65535");
        }
        u.port = p;
    }
    if (u.host.empty()) bad(url, "no host");
    if (u.host.find('/') != std::string::npos) bad(url, "a broker URL has no path");
    std::size_t start = 0;
    while (start < query.size()) {
        const auto amp = query.find('&', start);
        const std::string item = query.substr(start, amp == std::string::npos ? amp : amp - start);
        start = amp == std::string::npos ? query.size() : amp + 1;
        const auto eq = item.find('=');
        const std::string key = item.substr(0, eq);
        const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
        if (key == "cafile") {
            if (!u.tls) bad(url, "cafile needs mqtts://");
            u.ca_file = value;
        } else if (key == "password_file") {
            std::ifstream in(value);
            if (!in || !std::getline(in, u.password))
                bad(url, "cannot read the password file " + value);
            if (!u.password.empty() && u.password.back() == '\r') u.password.pop_back();
            if (u.username.empty()) bad(url, "a password file needs a user name (mqtt://USER@...)");
        } else {
            bad(url, "unknown option \"" + key + "\" (cafile, password_file)");
        }
    }
    return u;
}

}  // namespace pathstream::host
