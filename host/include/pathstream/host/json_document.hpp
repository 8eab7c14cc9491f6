// Shared by the JSON readers: parsing with file:line:col errors, and the checks every reader
// repeats (unknown keys, error at a JSON Pointer).
#pragma once

#include <nlohmann/json.hpp>
#include <set>
#include <string>

namespace pathstream::host {

/// Parses `text`; a syntax error or an unrepresentable number becomes an InputError at the
/// offending place ("file:line:col: invalid JSON: ...").
nlohmann::json parse_json_document(const std::string& text, const std::string& file);

/// Error reporting against one parsed document. Holds references: `text` and `file` must
/// outlive it.
class JsonChecker {
public:
    JsonChecker(const std::string& text, const std::string& file) : text_(text), file_(file) {}

    /// Throws InputError at the value addressed by `pointer` (RFC 6901; "" for the root).
    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const;

    /// Throws at the first key of `object` not in `allowed`, listing the allowed ones.
    void only_keys(const nlohmann::json& object, const std::string& pointer,
                   const std::set<std::string>& allowed) const;

    const std::string& text() const { return text_; }
    const std::string& file() const { return file_; }

private:
    const std::string& text_;
    const std::string& file_;
};

}  // namespace pathstream::host
