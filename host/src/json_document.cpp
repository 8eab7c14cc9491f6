#include "pathstream/host/json_document.hpp"

#include "pathstream/host/input_error.hpp"

namespace pathstream::host {

namespace {

// What nlohmann::json accepts but a pathstream document must not contain: a key twice in
// one object (nlohmann keeps the last) and bytes after the value (it stops at a NUL byte).
void check_strict(const std::string& text, const std::string& file, const JsonIndex& index) {
    if (const auto at = index.duplicate_key()) {
        throw InputError(file, index.location_of(*at), "duplicate key in one object");
    }
    if (const auto at = index.trailing_byte()) {
        const std::string what = text[*at] == '\0' ? "a NUL byte" : "bytes";
        throw InputError(file, index.location_of(*at),
                         "invalid JSON: " + what + " after the document");
    }
}

}  // namespace

nlohmann::json parse_json_document(const std::string& text, const std::string& file) {
    using nlohmann::json;
    json document;
    try {
        document = json::parse(text);
    } catch (const json::parse_error& e) {
        // nlohmann reports the byte just past the offending token; point at that token.
        const std::size_t offset = e.byte > 0 ? e.byte - 1 : 0;
        std::string message = e.what();
        if (const auto at = message.find("syntax error"); at != std::string::npos)
            message = message.substr(at);
        throw InputError(file, JsonIndex(text).location_of(offset), "invalid JSON: " + message);
    } catch (const json::out_of_range& e) {
        // A number too large for a double (e.g. 1e400): nlohmann names the token, not where.
        const std::string message = e.what();
        const auto open = message.find('\''), close = message.rfind('\'');
        if (open != std::string::npos && close > open) {
            const std::string token = message.substr(open + 1, close - open - 1);
            const auto at = text.find(token);
            throw InputError(
                file, at == std::string::npos ? SourceLocation{} : JsonIndex(text).location_of(at),
                "number " + token + " is out of range (not finite as a double)");
        }
        throw InputError(file, {}, "invalid JSON: " + message);
    }
    check_strict(text, file, JsonIndex(text));
    return document;
}

const JsonIndex& JsonChecker::index() const {
    if (!index_) index_.emplace(text_);
    return *index_;
}

void JsonChecker::fail(const std::string& pointer, const std::string& message) const {
    throw InputError(file_, locate(pointer), message);
}

void JsonChecker::only_keys(const nlohmann::json& object, const std::string& pointer,
                            const std::set<std::string>& allowed) const {
    for (const auto& [key, value] : object.items()) {
        if (!allowed.count(key)) {
            std::string list;
            for (const auto& k : allowed) list += (list.empty() ? "" : ", ") + k;
            fail(pointer + "/" + key,
                 "unknown key \"" + key + "\" (expected one of: " + list + ")");
        }
    }
}

}  // namespace pathstream::host
