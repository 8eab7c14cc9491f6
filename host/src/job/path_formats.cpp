// The path formats, one table, and reading a request's file by it: --format, else the extension,
// else (standard input) the first characters.
#include "pathstream/host/path_formats.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <system_error>

#include "pathstream/host/bpt_path.hpp"
#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {
namespace {

PathBasis basis_from_name(const std::string& name) {
    if (name == "catmull-rom") return PathBasis::kCatmullRom;
    if (name == "bezier") return PathBasis::kBezier;
    if (name == "polyline") return PathBasis::kPolyline;
    return PathBasis::kBSpline;
}

/// The G-code reader's options from the command line's.
GcodeOptions gcode_options(const JobRequest& o) {
    GcodeOptions g;
    if (!o.gcode_axes.empty()) g.axes = o.gcode_axes;
    const bool z_axis = g.axes.find('Z') != std::string::npos;
    g.pen = o.gcode_pen == "spindle"        ? PenControl::kSpindle
            : o.gcode_pen == "motion"       ? PenControl::kMotion
            : o.gcode_pen == "auto"         ? PenControl::kAuto
            : o.gcode_pen == "machine"      ? PenControl::kMachine
            : o.gcode_pen.empty() && z_axis ? PenControl::kMachine
                                            : PenControl::kZ;
    g.rapid_feed = o.gcode_rapid_feed;
    g.tool_table = o.gcode_tool_table;
    g.subroutine_path = o.gcode_subroutine_path;
    if (g.subroutine_path.empty() && o.file != "-") {
        const std::filesystem::path dir = std::filesystem::path(o.file).parent_path();
        g.subroutine_path.push_back(dir.empty() ? "." : dir.string());
    }
    g.z_down_max = o.gcode_z_down;
    g.arc_tolerance_mm = o.tolerance;
    g.ignore_codes = o.gcode_ignore;
    return g;
}

/// A G-code program's path: its warnings printed, its pen mode noted in `gcode_pen`.
Path read_gcode(const std::string& text, const std::string& name, const JobRequest& o,
                std::string& gcode_pen) {
    GcodeReadInfo info;
    Path path = parse_gcode_path(text, name, gcode_options(o), &info);
    for (const std::string& warning : info.warnings)
        std::cerr << "pathstream: warning: " << warning << '\n';
    gcode_pen = std::string(pen_control_name(info.pen)) + " (" + info.pen_reason + ")";
    return path;
}

Path read_json(const std::string& text, const std::string& name, const JobRequest& o,
               std::string&) {
    return parse_json_path(text, name, o.tolerance);
}

/// What the drawing has and the plot will not (text, images, clips it cannot apply): said once
/// per kind, never dropped in silence.
Path read_svg(const std::string& text, const std::string& name, const JobRequest& o, std::string&) {
    svg::SvgReadInfo info;
    Path path = parse_svg_path(text, name, o.tolerance, &info);
    for (const std::string& warning : info.warnings)
        std::cerr << "pathstream: warning: " << warning << '\n';
    return path;
}

Path read_csv(const std::string& text, const std::string& name, const JobRequest& o, std::string&) {
    return parse_csv_path(text, name, basis_from_name(o.csv_basis), o.csv_closed);
}

Path read_bpt(const std::string& text, const std::string& name, const JobRequest& o, std::string&) {
    BptOptions options;
    options.tolerance_mm = o.tolerance;
    return parse_bpt_path(text, name, options);
}

// Everything `in` holds, appended in blocks to a string reserved for `size_hint` bytes: no
// second copy of the text (a string stream's buffer and then its str() held two or three).
std::string read_all(std::istream& in, std::size_t size_hint) {
    std::string text;
    text.reserve(size_hint);
    char block[1 << 16];
    while (in.read(block, sizeof block) || in.gcount() > 0)
        text.append(block, static_cast<std::size_t>(in.gcount()));
    return text;
}

}  // namespace

const std::vector<PathFormat>& path_formats() {
    static const std::vector<PathFormat> formats = {
        {"json", {"json"}, "JSON paths, NURBS included (docs/formats.md)", read_json},
        {"csv", {"csv"}, "CSV points with a basis (docs/formats.md)", read_csv},
        {"svg", {"svg"}, "SVG drawings with layers (docs/formats-svg.md)", read_svg},
        {"gcode", {"gcode", "ngc", "nc", "gc"}, "RS274NGC G-code (docs/formats.md)", read_gcode},
        {"bpt",
         {"bpt"},
         "Bezier patches, the teapot's text form (docs/formats-surfaces.md)",
         read_bpt},
    };
    return formats;
}

std::string format_of_file_name(const std::string& name) {
    const std::size_t dot = name.find_last_of('.');
    if (dot == std::string::npos || name.find('/', dot) != std::string::npos) return "";
    std::string ext = name.substr(dot + 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    for (const PathFormat& f : path_formats()) {
        for (const std::string& e : f.extensions) {
            if (e == ext) return f.name;
        }
    }
    return "";
}

std::string path_extension_list() {
    std::vector<std::string> all;
    for (const PathFormat& f : path_formats()) {
        for (const std::string& e : f.extensions) all.push_back("." + e);
    }
    std::string text;
    for (std::size_t i = 0; i < all.size(); ++i)
        text += (i == 0 ? "" : i + 1 == all.size() ? " or " : ", ") + all[i];
    return text;
}

// The format standard input holds, from its first characters: SVG starts with '<', JSON with
// '{' or '[', CSV has a comma on its first line, anything else is taken as G-code.
std::string sniff_path_format(const std::string& text) {
    const std::size_t first = text.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
    if (first == std::string::npos) return "";
    if (text[first] == '<') return "svg";
    if (text[first] == '{' || text[first] == '[') return "json";
    const std::string line = text.substr(first, text.find('\n', first) - first);
    if (line.find(',') != std::string::npos) return "csv";
    return "gcode";
}

// The whole file, or standard input for "-".
std::string read_path_text(const std::string& file) {
    if (file == "-") return read_all(std::cin, 0);
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(file, error);
    std::string text = read_all(
        in, !error && size < (std::uintmax_t{1} << 40) ? static_cast<std::size_t>(size) : 0);
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return text;
}

// A file's format: --format, else its extension (standard input: --format or "").
std::string request_format(const JobRequest& o) {
    if (!o.format.empty() || o.file == "-") return o.format;
    const std::size_t dot = o.file.find_last_of('.');
    std::string ext = o.file.substr(dot == std::string::npos ? o.file.size() : dot);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    const std::string format = format_of_file_name(o.file);
    if (!format.empty()) return format;
    throw InputError(o.file, {},
                     "unknown file type \"" + ext + "\" (expected " + path_extension_list() + ")");
}

Path read_request_path(const JobRequest& o, std::string& gcode_pen, std::string& format) {
    format = request_format(o);  // an unknown extension is refused before reading
    const std::string text = read_path_text(o.file);
    const std::string name = path_display_name(o.file);
    if (format.empty()) format = sniff_path_format(text);
    if (format.empty()) throw InputError(name, {}, "standard input is empty: no path to read");
    for (const PathFormat& f : path_formats()) {
        if (f.name == format) return f.read(text, name, o, gcode_pen);
    }
    throw InputError(name, {}, "unknown format \"" + format + "\"");
}

std::string read_path_input(const JobRequest& o, std::string& format) {
    format = request_format(o);
    std::string text = read_path_text(o.file);
    if (format.empty()) format = sniff_path_format(text);
    return text;
}

}  // namespace pathstream::host
