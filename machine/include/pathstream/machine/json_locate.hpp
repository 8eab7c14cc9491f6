// Finds where a JSON value sits in its source text, so errors found after parsing (wrong
// type, bad range) can still say file:line:col, and enforces what nlohmann::json lets pass
// (duplicate keys, bytes after the document).
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "pathstream/machine/source_location.hpp"

namespace pathstream::host {

/// Where every value of a JSON text starts and where every line starts, found in one pass.
/// Building costs O(text size) time and memory; a lookup costs O(pointer depth x keys of the
/// objects on the way + log lines). Holds no reference to the text.
class JsonIndex {
public:
    /// Scans `text`, which nlohmann::json has already accepted as a prefix (it stops at a NUL
    /// byte). Duplicate keys and bytes after the root value are recorded, not thrown. Values
    /// nested deeper than `max_depth` (the root: 0) are not indexed: offset_of finds none.
    explicit JsonIndex(std::string_view text, std::size_t max_depth = static_cast<std::size_t>(-1));

    /// Offset of the value at JSON Pointer `pointer` (RFC 6901, "" for the root), if any.
    std::optional<std::size_t> offset_of(const std::string& pointer) const;
    /// Line and column (1-based, column in bytes) of byte `offset`.
    SourceLocation location_of(std::size_t offset) const;
    /// location_of(offset_of(pointer)), or {0, 0} when no value sits there.
    SourceLocation locate(const std::string& pointer) const;

    /// Offset of the first key that repeats an earlier key of its object, if any.
    std::optional<std::size_t> duplicate_key() const { return duplicate_key_; }
    /// Offset of the first byte after the root value that is not white space, if any.
    std::optional<std::size_t> trailing_byte() const { return trailing_byte_; }

private:
    friend class JsonIndexBuilder;
    struct Node {
        std::size_t offset = 0;
        bool object = false;
        std::vector<std::string> keys;      ///< members' keys (objects), in file order
        std::vector<std::size_t> children;  ///< members' or elements' node indices
    };
    std::vector<Node> nodes_;
    std::vector<std::size_t> line_starts_;
    std::optional<std::size_t> duplicate_key_, trailing_byte_;
};

/// Bytes JSON indexing and location lookups have read on this thread since it started: lets
/// tests check that reading a document costs a bounded number of passes over it.
std::size_t json_bytes_scanned();

}  // namespace pathstream::host
