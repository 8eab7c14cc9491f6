// Reader of CSV point lists: one point per line, "x,y[,z...]" (docs/formats-csv.md).
#pragma once

#include <string>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// Parses a CSV point list into a path of one subpath with the given `basis` and `closed`.
/// Lines hold 1 to 8 comma-separated numbers in mm (the same count on every line); the first
/// content line is a header when none of its fields is a number; blank lines and lines
/// starting with '#' are skipped. `file` names the source in error messages.
/// Throws InputError ("file:line:col: what is wrong", at the bad field) for fields that are
/// empty, not numbers, not finite or out of range (|value| > 1e6 mm), rows with another column
/// count, more than 8 columns, and too few points for the basis.
Path parse_csv_path(const std::string& text, const std::string& file, PathBasis basis, bool closed);

/// Reads and parses a CSV file. Throws as parse_csv_path, and InputError when the file cannot
/// be read.
Path load_csv_path(const std::string& file, PathBasis basis, bool closed);

}  // namespace pathstream::host
