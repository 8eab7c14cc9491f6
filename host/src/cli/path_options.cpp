#include "path_options.hpp"

#include <charconv>
#include <filesystem>
#include <system_error>

#include "pathstream/host/path_formats.hpp"

namespace pathstream::host {

void add_path_options(CLI::App& command, JobRequest& o) {
    command
        .add_option("file", o.file,
                    "path file: .json, .csv, .svg, .gcode/.ngc/.nc/.gc (docs/formats.md); -: "
                    "standard input")
        ->required()
        ->check(CLI::Validator(
            [](std::string& file) -> std::string {
                // One plain sentence: CLI11's "(... not in {-}) OR (File does not exist ...)"
                // read like two errors.
                if (file == "-") return "";
                std::error_code error;
                const auto status = std::filesystem::status(file, error);
                if (!std::filesystem::exists(status)) return "no such file: " + file;
                if (std::filesystem::is_directory(status))
                    return file + " is a directory, not a path file";
                return "";
            },
            "FILE or -"));
    command
        .add_option("--format", o.format,
                    "the path file's format when its name does not tell (or for -)")
        ->check(CLI::IsMember([] {
            std::vector<std::string> names;
            for (const PathFormat& f : path_formats()) names.push_back(f.name);
            return names;
        }()));
    command.add_option("--csv-basis", o.csv_basis, "basis of CSV points")
        ->capture_default_str()
        ->check(CLI::IsMember({"bspline", "catmull-rom", "bezier", "polyline"}));
    command.add_flag("--csv-closed", o.csv_closed, "CSV points form a closed curve");
    command
        .add_option("--gcode-pen", o.gcode_pen,
                    "G-code pen control: z (down at Z <= --gcode-z-down), spindle (M3/M5), "
                    "motion (G1 draws, G0 travels), machine (every move in the program's order, "
                    "Z an axis when the machine has one) or auto (chosen from the file); "
                    "default: z, machine on a machine with a z axis")
        ->check(CLI::IsMember({"z", "spindle", "motion", "machine", "auto"}));
    command.add_option("--subroutine-path", o.gcode_subroutine_path,
                       "G-code: directory searched for NAME.ngc when the program calls a "
                       "subroutine it does not define (repeatable; default: the program's own)");
    command
        .add_option("--tool-table", o.gcode_tool_table,
                    "G-code: LinuxCNC tool table file that G43 H reads")
        ->check(CLI::ExistingFile);
    command.add_option("--ignore-code", o.gcode_ignore,
                       "G-code: skip this G or M code with a warning, like M300 (repeatable; M6 on "
                       "a plotter, M7-M9 and "
                       "others are skipped already)");
    command
        .add_option("--gcode-z-down", o.gcode_z_down, "G-code: highest Z (mm) with the pen down")
        ->capture_default_str();
    command
        .add_option("--tolerance", o.tolerance, "mm: arcs (SVG, G-code) become cubics within this")
        ->capture_default_str()
        ->check(CLI::Range(1e-6, 10.0));
    // Placement (applied in this order: rotate, flip-y, scale or fit, align, translate).
    command
        .add_option("--rotate", o.placement.rotate,
                    "placement: rotate by 90, 180 or 270 degrees about the origin (x towards y)")
        ->check(CLI::IsMember({0, 90, 180, 270}));
    command.add_flag("--flip-y", o.placement.flip_y, "placement: mirror y (y -> -y)");
    command
        .add_option("--scale", o.placement.scale,
                    "placement: scale x and y by this factor about the origin")
        ->check(CLI::PositiveNumber);
    CLI::Option* fit =
        command.add_option("--fit", o.placement.fit,
                           "placement: scale (keeping the aspect) and align into: area (the "
                           "machine's work area, needs "
                           "--machine) or a paper a0..a6, letter, legal, tabloid (add -landscape)");
    command
        .add_option("--margin", o.placement.margin,
                    "placement: mm kept free on every side with --fit")
        ->check(CLI::NonNegativeNumber)
        ->needs(fit);
    command
        .add_option("--align", o.placement.align,
                    "placement: where in the --fit box (default center); without --fit, that point "
                    "of the drawing "
                    "goes to (0, 0)")
        ->check(CLI::IsMember({"center", "top-left", "top", "top-right", "left", "right",
                               "bottom-left", "bottom", "bottom-right"}));
    command
        .add_option("--origin", o.placement.origin,
                    "placement: the machine's origin corner, top-left (y down, as SVG) or "
                    "bottom-left (y up); "
                    "decides what top means for --align")
        ->capture_default_str()
        ->check(CLI::IsMember({"top-left", "bottom-left"}));
    command.add_option("--translate", o.translate, "placement: X,Y mm added last");
    // Order (docs/path-order.md).
    CLI::Option* keep = command.add_flag(
        "--keep-order", o.keep_order, "draw the subpaths in file order, as given (no reordering)");
    command
        .add_flag("--order", o.order,
                  "order the subpaths for less pen-up travel where the default keeps the file's "
                  "order (G-code, "
                  "eval, setpoints)")
        ->excludes(keep);
    command
        .add_option("--merge-tolerance", o.merge_tolerance,
                    "mm: open polyline/Bezier subpaths whose ends are this close are joined (0: "
                    "exact only)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 10.0));
    command.add_option(
        "--order-start", o.order_start,
        "X,Y mm: where the pen is before the first subpath, for the order (default: the origin)");
    command.add_option(
        "--layer", o.layers,
        "plot only this layer (its name, or its number from 1; repeatable); placement still "
        "uses the whole drawing, so layers plotted in separate runs line up");
    command
        .add_option(
            "--pause", o.pause,
            "pause for a pen change between layers: pen (where their stroke colours differ), layer "
            "(between every two), none")
        ->capture_default_str()
        ->check(CLI::IsMember({"pen", "layer", "none"}));
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
