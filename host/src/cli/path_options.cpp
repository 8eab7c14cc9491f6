#include "path_options.hpp"

#include <algorithm>
#include <charconv>
#include <cctype>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/input_error.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/svg_path.hpp"

namespace pathstream::host {

void add_path_options(CLI::App& command, PathOptions& o) {
    command
        .add_option("file", o.file,
                    "path file: .json, .csv, .svg, .gcode/.ngc/.nc/.gc (docs/formats.md)")
        ->required()
        ->check(CLI::ExistingFile);
    command.add_option("--csv-basis", o.csv_basis, "basis of CSV points")
        ->capture_default_str()
        ->check(CLI::IsMember({"bspline", "catmull-rom", "bezier", "polyline"}));
    command.add_flag("--csv-closed", o.csv_closed, "CSV points form a closed curve");
    command.add_option("--gcode-pen", o.gcode_pen, "G-code pen control: z (down at Z <= --gcode-z-down) or spindle (M3/M5)")
        ->capture_default_str()
        ->check(CLI::IsMember({"z", "spindle"}));
    command.add_option("--gcode-z-down", o.gcode_z_down, "G-code: highest Z (mm) with the pen down")->capture_default_str();
    command.add_option("--tolerance", o.tolerance, "mm: arcs (SVG, G-code) become cubics within this")
        ->capture_default_str()
        ->check(CLI::Range(1e-6, 10.0));
}

namespace {
PathBasis basis_from_name(const std::string& name) {
    if (name == "catmull-rom") return PathBasis::kCatmullRom;
    if (name == "bezier") return PathBasis::kBezier;
    if (name == "polyline") return PathBasis::kPolyline;
    return PathBasis::kBSpline;
}
}  // namespace

Path load_path(const PathOptions& o) {
    std::string ext = o.file.substr(o.file.find_last_of('.') == std::string::npos ? o.file.size()
                                                                                 : o.file.find_last_of('.'));
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".json") return load_json_path(o.file);
    if (ext == ".svg") return load_svg_path(o.file, o.tolerance);
    if (ext == ".csv") return load_csv_path(o.file, basis_from_name(o.csv_basis), o.csv_closed);
    if (ext == ".gcode" || ext == ".ngc" || ext == ".nc" || ext == ".gc") {
        GcodeOptions g;
        g.pen = o.gcode_pen == "spindle" ? PenControl::kSpindle : PenControl::kZ;
        g.z_down_max = o.gcode_z_down;
        g.arc_tolerance_mm = o.tolerance;
        return load_gcode_path(o.file, g);
    }
    throw InputError(
        o.file, {},
        "unknown file type \"" + ext + "\" (expected .json, .csv, .svg, .gcode, .ngc, .nc or .gc)");
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
