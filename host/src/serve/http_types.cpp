#include "http_types.hpp"

namespace pathstream::host::serve {
namespace {

int hex_digit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

std::string decoded(const std::string& text, std::size_t from, std::size_t to) {
    std::string out;
    out.reserve(to - from);
    for (std::size_t i = from; i < to; ++i) {
        const char c = text[i];
        if (c == '+') {
            out += ' ';
        } else if (c == '%' && i + 2 < to && hex_digit(text[i + 1]) >= 0 &&
                   hex_digit(text[i + 2]) >= 0) {
            out += static_cast<char>(hex_digit(text[i + 1]) * 16 + hex_digit(text[i + 2]));
            i += 2;
        } else {
            out += c;
        }
    }
    return out;
}

}  // namespace

std::string HttpRequest::header(const std::string& name) const {
    for (const auto& [n, v] : headers) {
        if (n == name) return v;
    }
    return "";
}

std::string HttpRequest::param(const std::string& name) const {
    const auto it = query.find(name);
    return it == query.end() ? std::string() : it->second;
}

std::map<std::string, std::string> parse_query(const std::string& query) {
    std::map<std::string, std::string> out;
    std::size_t at = 0;
    while (at <= query.size()) {
        const std::size_t end = std::min(query.find('&', at), query.size());
        if (end > at) {
            const std::size_t eq = std::min(query.find('=', at), end);
            out.emplace(decoded(query, at, eq),
                        eq < end ? decoded(query, eq + 1, end) : std::string());
        }
        at = end + 1;
    }
    return out;
}

std::string cookie_value(const std::string& cookies, const std::string& name) {
    std::size_t at = 0;
    while (at < cookies.size()) {
        const std::size_t end = std::min(cookies.find(';', at), cookies.size());
        std::size_t start = at;
        while (start < end && cookies[start] == ' ') ++start;
        if (end - start > name.size() && cookies.compare(start, name.size(), name) == 0 &&
            cookies[start + name.size()] == '=') {
            return cookies.substr(start + name.size() + 1, end - start - name.size() - 1);
        }
        at = end + 1;
    }
    return "";
}

}  // namespace pathstream::host::serve
