// Shared by the JSON readers: parsing with file:line:col errors, and the checks every reader
// repeats (unknown keys, error at a JSON Pointer).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>

#include "pathstream/host/json_locate.hpp"

namespace pathstream::host {

/// Parses `text` strictly: a syntax error, an unrepresentable number, a key repeated in one
/// object or anything but white space after the value (a NUL byte included) becomes an
/// InputError at the offending place ("file:line:col: ..."). O(text size).
nlohmann::json parse_json_document(const std::string& text, const std::string& file);

/// Error reporting against one parsed document. Holds references: `text` and `file` must
/// outlive it. Locations come from one JsonIndex, built on first use: O(text size) once.
class JsonChecker {
public:
    JsonChecker(const std::string& text, const std::string& file) : text_(text), file_(file) {}

    /// Throws InputError at the value addressed by `pointer` (RFC 6901; "" for the root).
    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const;

    /// Throws at the first key of `object` not in `allowed`, listing the allowed ones.
    void only_keys(const nlohmann::json& object, const std::string& pointer,
                   const std::set<std::string>& allowed) const;

    /// Line and column of the value at `pointer`, {0, 0} if none.
    SourceLocation locate(const std::string& pointer) const { return index().locate(pointer); }

    const std::string& text() const { return text_; }
    const std::string& file() const { return file_; }

private:
    const JsonIndex& index() const;

    const std::string& text_;
    const std::string& file_;
    mutable std::optional<JsonIndex> index_;
};

}  // namespace pathstream::host
