// Reader of the JSON path format (docs/formats.md).
#pragma once

#include <string>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// Parses a JSON path document. `file` names the source in error messages.
/// Throws InputError ("file:line:col: what is wrong") on malformed JSON, unknown keys,
/// wrong types, non-finite or out-of-range numbers, too few points and unknown bases.
Path parse_json_path(const std::string& text, const std::string& file);

/// Reads and parses a JSON path file. Throws InputError, also when it cannot be read.
Path load_json_path(const std::string& file);

}  // namespace pathstream::host
