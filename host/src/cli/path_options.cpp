#include "path_options.hpp"

#include <algorithm>
#include <charconv>
#include <cctype>

#include "pathstream/host/input_error.hpp"
#include "pathstream/host/json_path.hpp"

namespace pathstream::host {

void add_path_options(CLI::App& command, PathOptions& o) {
    command.add_option("file", o.file, "path file: .json, .csv, .svg, .gcode/.ngc/.nc (docs/formats.md)")
        ->required()
        ->check(CLI::ExistingFile);
}

Path load_path(const PathOptions& o) {
    std::string ext = o.file.substr(o.file.find_last_of('.') == std::string::npos ? o.file.size()
                                                                                 : o.file.find_last_of('.'));
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".json") return load_json_path(o.file);
    throw InputError(o.file, {}, "unknown file type \"" + ext + "\" (expected .json, .csv, .svg, .gcode, .ngc or .nc)");
}

const char* axis_column_name(std::size_t axis) {
    static const char* const kNames[] = {"x", "y", "z", "a", "b", "c", "v", "w"};
    return axis < 8 ? kNames[axis] : "?";
}

std::string exact_decimal(double value) {
    char buffer[32];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    return std::string(buffer, result.ptr);
}

}  // namespace pathstream::host
