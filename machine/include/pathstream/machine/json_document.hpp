// Shared by the JSON readers: parsing with file:line:col errors, and the checks every reader
// repeats (unknown keys, error at a JSON Pointer).
#pragma once

#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "pathstream/machine/json_locate.hpp"

namespace pathstream::host {

/// Arrays of number arrays ([[x, y], [x, y], ...]) read flat instead of into the document
/// tree: 10^6 points are ~100 MB as a tree, 16 MB flat.
struct FlatNumberArrays {
    /// Where such arrays may be: JSON Pointers, "*" standing for any array index (e.g.
    /// "/subpaths/*/points"). An array there holding anything else (a number at the top, a
    /// string, an object, an array in a row, a row of more than 255 numbers) is read into the
    /// document as usual, its numbers as floating point.
    std::vector<std::string> where;
    struct Rows {
        std::vector<double> values;        ///< every row's numbers, one row after another
        std::vector<std::uint8_t> widths;  ///< numbers per row
    };
    /// The arrays read flat, by JSON Pointer: the document holds an empty array in their place.
    std::map<std::string, Rows> found;
};

/// Parses `text` strictly: a syntax error, an unrepresentable number, a key repeated in one
/// object or anything but white space after the value (a NUL byte included) becomes an
/// InputError at the offending place ("file:line:col: ..."). O(text size). With `flat`, the
/// arrays it names are read flat (the errors are the same).
nlohmann::json parse_json_document(const std::string& text, const std::string& file,
                                   FlatNumberArrays* flat = nullptr);

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
    SourceLocation locate(const std::string& pointer) const;

    /// Pointers of at most `depth` tokens are located in an index of the values that shallow
    /// only (the others, as by default, in one of every value): a reader that locates only its
    /// outer values in a large document then indexes them, not every number.
    void locate_shallow(std::size_t depth) const { shallow_depth_ = depth; }

    const std::string& text() const { return text_; }
    const std::string& file() const { return file_; }

private:
    const JsonIndex& index() const;

    const std::string& text_;
    const std::string& file_;
    mutable std::optional<JsonIndex> index_;
    mutable std::optional<JsonIndex> shallow_;
    mutable std::optional<std::size_t> shallow_depth_;
};

}  // namespace pathstream::host
