// Finds where a JSON value sits in its source text, so errors found after parsing (wrong
// type, bad range) can still say file:line:col.
#pragma once

#include <string>
#include <string_view>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// Line and column (1-based) of the value at JSON Pointer `pointer` (RFC 6901, e.g.
/// "/subpaths/0/points/3/1") in `text`, or of a byte `offset`. Returns {0, 0} if not found.
SourceLocation locate_json_pointer(std::string_view text, const std::string& pointer);
SourceLocation locate_offset(std::string_view text, std::size_t offset);

}  // namespace pathstream::host
