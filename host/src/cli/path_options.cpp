#include "path_options.hpp"

#include <algorithm>
#include <charconv>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <system_error>
#include <fstream>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/svg_path.hpp"

namespace pathstream::host {

void add_path_options(CLI::App& command, PathOptions& o) {
    command
        .add_option("file", o.file,
                    "path file: .json, .csv, .svg, .gcode/.ngc/.nc/.gc (docs/formats.md); -: standard input")
        ->required()
        ->check(CLI::Validator(
            [](std::string& file) -> std::string {
                // One plain sentence: CLI11's "(... not in {-}) OR (File does not exist ...)"
                // read like two errors.
                if (file == "-") return "";
                std::error_code error;
                const auto status = std::filesystem::status(file, error);
                if (!std::filesystem::exists(status)) return "no such file: " + file;
                if (std::filesystem::is_directory(status)) return file + " is a directory, not a path file";
                return "";
            },
            "FILE or -"));
    command.add_option("--format", o.format, "the path file's format when its name does not tell (or for -)")
        ->check(CLI::IsMember({"json", "csv", "svg", "gcode"}));
    command.add_option("--csv-basis", o.csv_basis, "basis of CSV points")
        ->capture_default_str()
        ->check(CLI::IsMember({"bspline", "catmull-rom", "bezier", "polyline"}));
    command.add_flag("--csv-closed", o.csv_closed, "CSV points form a closed curve");
    command.add_option("--gcode-pen", o.gcode_pen, "G-code pen control: z (down at Z <= --gcode-z-down), spindle (M3/M5), "
                                                   "motion (G1 draws, G0 travels) or auto (chosen from the file)")
        ->capture_default_str()
        ->check(CLI::IsMember({"z", "spindle", "motion", "auto"}));
    command.add_option("--ignore-code", o.gcode_ignore,
                       "G-code: skip this G or M code with a warning, like M300 (repeatable; M6, M7-M9 and "
                       "others are skipped already)");
    command.add_option("--gcode-z-down", o.gcode_z_down, "G-code: highest Z (mm) with the pen down")->capture_default_str();
    command.add_option("--tolerance", o.tolerance, "mm: arcs (SVG, G-code) become cubics within this")
        ->capture_default_str()
        ->check(CLI::Range(1e-6, 10.0));
    // Placement (applied in this order: rotate, flip-y, scale or fit, align, translate).
    command.add_option("--rotate", o.placement.rotate, "placement: rotate by 90, 180 or 270 degrees about the origin (x towards y)")
        ->check(CLI::IsMember({0, 90, 180, 270}));
    command.add_flag("--flip-y", o.placement.flip_y, "placement: mirror y (y -> -y)");
    command.add_option("--scale", o.placement.scale, "placement: scale x and y by this factor about the origin")
        ->check(CLI::PositiveNumber);
    CLI::Option* fit = command.add_option("--fit", o.placement.fit,
                       "placement: scale (keeping the aspect) and align into: area (the machine's work area, needs "
                       "--machine) or a paper a0..a6, letter, legal, tabloid (add -landscape)");
    command.add_option("--margin", o.placement.margin, "placement: mm kept free on every side with --fit")
        ->check(CLI::NonNegativeNumber)
        ->needs(fit);
    command.add_option("--align", o.placement.align,
                       "placement: where in the --fit box (default center); without --fit, that point of the drawing "
                       "goes to (0, 0)")
        ->check(CLI::IsMember({"center", "top-left", "top", "top-right", "left", "right", "bottom-left", "bottom",
                               "bottom-right"}));
    command.add_option("--origin", o.placement.origin,
                       "placement: the machine's origin corner, top-left (y down, as SVG) or bottom-left (y up); "
                       "decides what top means for --align")
        ->capture_default_str()
        ->check(CLI::IsMember({"top-left", "bottom-left"}));
    command.add_option("--translate", o.translate, "placement: X,Y mm added last");
    // Order (docs/path-order.md).
    CLI::Option* keep = command.add_flag("--keep-order", o.keep_order,
                                         "draw the subpaths in file order, as given (no reordering)");
    command
        .add_flag("--order", o.order,
                  "order the subpaths for less pen-up travel where the default keeps the file's order (G-code, "
                  "eval, setpoints)")
        ->excludes(keep);
    command.add_option("--merge-tolerance", o.merge_tolerance,
                       "mm: open polyline/Bezier subpaths whose ends are this close are joined (0: exact only)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 10.0));
    command.add_option("--order-start", o.order_start,
                       "X,Y mm: where the pen is before the first subpath, for the order (default: the origin)");
    command.add_option("--layer", o.layers,
                       "plot only this layer (its name, or its number from 1; repeatable); placement still "
                       "uses the whole drawing, so layers plotted in separate runs line up");
    command.add_option("--pause", o.pause,
                       "pause for a pen change between layers: pen (where their stroke colours differ), layer "
                       "(between every two), none")
        ->capture_default_str()
        ->check(CLI::IsMember({"pen", "layer", "none"}));
}

namespace {
PathBasis basis_from_name(const std::string& name) {
    if (name == "catmull-rom") return PathBasis::kCatmullRom;
    if (name == "bezier") return PathBasis::kBezier;
    if (name == "polyline") return PathBasis::kPolyline;
    return PathBasis::kBSpline;
}
}  // namespace

namespace {
/// Comma-separated finite numbers ("10,-2.5"); `option` names it in errors.
std::vector<double> parse_numbers(const std::string& text, const std::string& option) {
    std::vector<double> values;
    std::size_t at = 0;
    while (at <= text.size()) {
        const std::size_t comma = std::min(text.find(',', at), text.size());
        const std::string item = text.substr(at, comma - at);
        double v = 0;
        const auto [end, error] = std::from_chars(item.data(), item.data() + item.size(), v);
        if (item.empty() || error != std::errc() || end != item.data() + item.size() || !std::isfinite(v)) {
            throw std::invalid_argument(option + ": \"" + text + "\" is not a comma-separated list of numbers (mm)");
        }
        values.push_back(v);
        at = comma + 1;
    }
    return values;
}

/// The file as its reader gives it, by extension; `gcode_pen` gets the G-code pen mode note.
Path read_path(const PathOptions& o, std::string& gcode_pen, std::string& format);

/// The G-code reader's options from the command line's.
GcodeOptions gcode_options(const PathOptions& o) {
    GcodeOptions g;
    g.pen = o.gcode_pen == "spindle" ? PenControl::kSpindle
            : o.gcode_pen == "motion" ? PenControl::kMotion
            : o.gcode_pen == "auto"   ? PenControl::kAuto
                                      : PenControl::kZ;
    g.z_down_max = o.gcode_z_down;
    g.arc_tolerance_mm = o.tolerance;
    g.ignore_codes = o.gcode_ignore;
    return g;
}

/// A G-code program's path: its warnings printed, its pen mode noted in `gcode_pen`.
Path read_gcode(const PathOptions& o, const std::string& text, std::string& gcode_pen) {
    GcodeReadInfo info;
    Path path = parse_gcode_path(text, path_display_name(o.file), gcode_options(o), &info);
    for (const std::string& warning : info.warnings) std::cerr << "pathstream: warning: " << warning << '\n';
    gcode_pen = std::string(pen_control_name(info.pen)) + " (" + info.pen_reason + ")";
    return path;
}
}  // namespace

LoadedPath load_path_report(const PathOptions& o, const MachineProfile* machine, const std::vector<double>* start) {
    LoadedPath loaded;
    std::string format;
    Path path = read_path(o, loaded.gcode_pen, format);
    PlacementOptions placement = o.placement;
    if (machine != nullptr) placement.edge_clearance = machine->chord_tolerance + machine->mm_per_lsb;
    if (!o.translate.empty()) {
        const std::vector<double> xy = parse_numbers(o.translate, "--translate");
        if (xy.size() != 2) throw std::invalid_argument("--translate: give X,Y (2 numbers), got \"" + o.translate + "\"");
        placement.translate = std::make_pair(xy[0], xy[1]);
    }
    loaded.placed = placement.active();
    const std::optional<Box2> area = machine != nullptr ? work_area(*machine) : std::nullopt;
    // Each step on the path only when it has something to do: a 10^6-point path is ~60 MB a copy.
    if (loaded.placed) path = place_path(path, placement, area, &loaded.placement);
    if (!o.layers.empty()) path = select_layers(path, o.layers);
    path = group_by_layer(std::move(path));
    pause_between_layers(path, o.pause == "layer"  ? LayerPause::kEveryLayer
                               : o.pause == "none" ? LayerPause::kNone
                                                   : LayerPause::kPenChange);
    if (machine != nullptr) apply_layer_feeds(path, *machine);
    if (o.keep_order) {
        loaded.kept_order_because = "--keep-order";
    } else if (!o.order && format == "gcode") {
        loaded.kept_order_because = "G-code keeps the program's order; --order to reorder";
    } else if (!o.order && o.keep_order_by_default) {
        loaded.kept_order_because = "this command keeps the file's order; --order to reorder";
    }
    if (loaded.kept_order_because.empty()) {
        OrderOptions order;
        order.merge_tolerance = o.merge_tolerance;
        if (!o.order_start.empty()) {
            order.start = parse_numbers(o.order_start, "--order-start");
            if (order.start.size() != path.axes) {
                throw std::invalid_argument("--order-start: give " + std::to_string(path.axes) +
                                            " coordinates (one per axis of the path), got \"" + o.order_start + "\"");
            }
        } else if (start != nullptr && start->size() == path.axes) {
            order.start = *start;
        }
        path = order_sections(std::move(path), order, &loaded.order);
        loaded.ordered = true;
    }
    loaded.path = std::move(path);
    return loaded;
}

Path load_path(const PathOptions& o, const MachineProfile* machine, const std::vector<double>* start) {
    return load_path_report(o, machine, start).path;
}

namespace {
// The format standard input holds, from its first characters: SVG starts with '<', JSON with
// '{' or '[', CSV has a comma on its first line, anything else is taken as G-code.
std::string sniff_format(const std::string& text) {
    const std::size_t first = text.find_first_not_of(" \t\r\n\xEF\xBB\xBF");
    if (first == std::string::npos) return "";
    if (text[first] == '<') return "svg";
    if (text[first] == '{' || text[first] == '[') return "json";
    const std::string line = text.substr(first, text.find('\n', first) - first);
    if (line.find(',') != std::string::npos) return "csv";
    return "gcode";
}

// Everything `in` holds, appended in blocks to a string reserved for `size_hint` bytes: no
// second copy of the text (a string stream's buffer and then its str() held two or three).
std::string read_all(std::istream& in, std::size_t size_hint) {
    std::string text;
    text.reserve(size_hint);
    char block[1 << 16];
    while (in.read(block, sizeof block) || in.gcount() > 0) text.append(block, static_cast<std::size_t>(in.gcount()));
    return text;
}

// The whole file, or standard input for "-".
std::string read_input(const std::string& file) {
    if (file == "-") return read_all(std::cin, 0);
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::error_code error;
    const std::uintmax_t size = std::filesystem::file_size(file, error);
    std::string text = read_all(in, !error && size < (std::uintmax_t{1} << 40) ? static_cast<std::size_t>(size) : 0);
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return text;
}

// A file's format: --format, else its extension (standard input: --format or "").
std::string file_format(const PathOptions& o) {
    if (!o.format.empty() || o.file == "-") return o.format;
    const std::size_t dot = o.file.find_last_of('.');
    std::string ext = o.file.substr(dot == std::string::npos ? o.file.size() : dot);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    if (ext == ".json" || ext == ".svg" || ext == ".csv") return ext.substr(1);
    if (ext == ".gcode" || ext == ".ngc" || ext == ".nc" || ext == ".gc") return "gcode";
    throw InputError(
        o.file, {},
        "unknown file type \"" + ext + "\" (expected .json, .csv, .svg, .gcode, .ngc, .nc or .gc)");
}

Path read_path(const PathOptions& o, std::string& gcode_pen, std::string& format) {
    format = file_format(o);  // an unknown extension is refused before reading
    const std::string text = read_input(o.file);
    const std::string name = path_display_name(o.file);
    if (format.empty()) format = sniff_format(text);
    if (format.empty()) throw InputError(name, {}, "standard input is empty: no path to read");
    if (format == "json") return parse_json_path(text, name, o.tolerance);
    if (format == "svg") {
        // What the drawing has and the plot will not (text, images, clips it cannot apply):
        // said once per kind, never dropped in silence.
        svg::SvgReadInfo info;
        Path path = parse_svg_path(text, name, o.tolerance, &info);
        for (const std::string& warning : info.warnings) std::cerr << "pathstream: warning: " << warning << '\n';
        return path;
    }
    if (format == "csv") return parse_csv_path(text, name, basis_from_name(o.csv_basis), o.csv_closed);
    return read_gcode(o, text, gcode_pen);
}
}  // namespace

std::string read_path_input(const PathOptions& o, std::string& format) {
    format = file_format(o);
    std::string text = read_input(o.file);
    if (format.empty()) format = sniff_format(text);
    return text;
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
