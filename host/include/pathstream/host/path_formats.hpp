// The path formats a job can be read from, in one table: name, file extensions, reader. The
// CLI's --format and help, the web server's upload check and the benches all read it.
#pragma once

#include <string>
#include <vector>

#include "pathstream/host/job_request.hpp"
#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// One format: its --format name, its file extensions (lower case, no dot) and its reader.
struct PathFormat {
    std::string name;                     ///< "json", "csv", "svg", "gcode"
    std::vector<std::string> extensions;  ///< "gcode", "ngc", "nc", "gc"
    std::string description;              ///< for help texts
    /// Reads `text` (named `name` in messages) with the request's options; G-code notes its pen
    /// mode and why in `note`. Throws InputError for bad input; prints the reader's warnings.
    Path (*read)(const std::string& text, const std::string& name, const JobRequest& request,
                 std::string& note);
};

/// Every format, in the order help texts list them. Constant after first use; any thread.
const std::vector<PathFormat>& path_formats();

/// The format a file name's extension names (case-insensitive), or "" for none.
std::string format_of_file_name(const std::string& name);

/// Every extension, for messages: ".json, .csv, .svg, .gcode, .ngc, .nc or .gc".
std::string path_extension_list();

/// The format standard input holds, from its first characters: SVG starts with '<', JSON with
/// '{' or '[', CSV has a comma on its first line, anything else is G-code; "" when empty.
std::string sniff_path_format(const std::string& text);

/// The whole file, or standard input for "-". Throws InputError when it cannot be read.
std::string read_path_text(const std::string& file);

/// A request's format: its `format`, else its file's extension ("" for standard input without
/// one). Throws InputError naming the extensions for an unknown one.
std::string request_format(const JobRequest& request);

/// The request's file read by its format (standard input sniffed); `format` gets the format
/// used, `gcode_pen` the G-code pen mode note. Throws InputError.
Path read_request_path(const JobRequest& request, std::string& gcode_pen, std::string& format);

}  // namespace pathstream::host
