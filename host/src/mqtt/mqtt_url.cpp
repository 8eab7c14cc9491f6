// MQTT broker URLs: scheme, credentials, host, port and the TLS and password-file options.
#include <charconv>
#include <fstream>

#include "pathstream/host/mqtt_client.hpp"

namespace pathstream::host {
namespace {

[[noreturn]] void bad(const std::string& url, const std::string& why) {
    throw std::invalid_argument("mqtt URL \"" + url + "\": " + why);
}

// The password file's first line, read at most 4 KiB: a file that is no password file (a
// device, a log) costs no more.
std::string first_line(const std::string& url, const std::string& path) {
    constexpr std::size_t kMax = 4096;
    std::ifstream in(path, std::ios::binary);
    if (!in) bad(url, "cannot read the password file " + path);
    std::string line;
    char c = 0;
    while (in.get(c) && c != '\n') {
        if (line.size() == kMax)
            bad(url, "the password file's first line is longer than 4096 bytes");
        line += c;
    }
    if (in.bad()) bad(url, "cannot read the password file " + path);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) bad(url, "the password file " + path + " has no password on its first line");
    return line;
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
            u.password = first_line(url, value);
            if (u.username.empty()) bad(url, "a password file needs a user name (mqtt://USER@...)");
        } else {
            bad(url, "unknown option \"" + key + "\" (cafile, password_file)");
        }
    }
    return u;
}

}  // namespace pathstream::host
