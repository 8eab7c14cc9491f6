#include "pathstream/host/json_document.hpp"

#include "pathstream/host/input_error.hpp"
#include "pathstream/host/json_locate.hpp"

namespace pathstream::host {

nlohmann::json parse_json_document(const std::string& text, const std::string& file) {
    using nlohmann::json;
    try {
        return json::parse(text);
    } catch (const json::parse_error& e) {
        // nlohmann reports the byte just past the offending token; point at that token.
        const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
        std::string message = e.what();
        if (const auto at = message.find("syntax error"); at != std::string::npos) message = message.substr(at);
        throw InputError(file, locate_offset(text, offset), "invalid JSON: " + message);
    } catch (const json::out_of_range& e) {
        // A number too large for a double (e.g. 1e400): nlohmann names the token, not where.
        const std::string message = e.what();
        const auto open = message.find('\''), close = message.rfind('\'');
        if (open != std::string::npos && close > open) {
            const std::string token = message.substr(open + 1, close - open - 1);
            const auto at = text.find(token);
            throw InputError(file, at == std::string::npos ? SourceLocation{} : locate_offset(text, at),
                             "number " + token + " is out of range (not finite as a double)");
        }
        throw InputError(file, {}, "invalid JSON: " + message);
    }
}

void JsonChecker::fail(const std::string& pointer, const std::string& message) const {
    throw InputError(file_, locate_json_pointer(text_, pointer), message);
}

void JsonChecker::only_keys(const nlohmann::json& object, const std::string& pointer,
                            const std::set<std::string>& allowed) const {
    for (const auto& [key, value] : object.items()) {
        if (!allowed.count(key)) {
            std::string list;
            for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
            fail(pointer + "/" + key, "unknown key \"" + key + "\" (expected one of: " + list + ")");
        }
    }
}

}  // namespace pathstream::host
