// A job as a user asks for it (JobRequest) and the path it loads: read by format, placed,
// split by layer, ordered. What the CLI's commands, `pathstream serve` and the benches share.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pathstream/host/path.hpp"
#include "pathstream/host/path_order.hpp"
#include "pathstream/host/placement.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// One job as a user asks for it: the path file and how to read, place, order and split it.
/// Plain values; every command, `serve` and the benches fill one and load it the same way.
struct JobRequest {
    std::string file;                   ///< the path file; "-": standard input
    std::string format;                 ///< --format: json, csv, svg or gcode; empty: by extension
    std::string csv_basis = "bspline";  ///< basis for CSV point files
    bool csv_closed = false;
    /// "z", "spindle" (M3/M5), "motion" (G1 draws), "machine" (every move in order, Z an axis
    /// when the machine has one) or "auto"; "": z on a machine without a Z axis, else machine.
    std::string gcode_pen;
    /// The path's axes as G-code letters ("XY", "XYZ"): set from the machine profile's axis
    /// names by load_path_report; empty: "XY".
    std::string gcode_axes;
    double gcode_rapid_feed =
        0;  ///< mm/s for G0 in machine mode (set from the profile); 0: travel_feed
    std::string gcode_tool_table;  ///< --tool-table: LinuxCNC tool table for G43 H
    /// --subroutine-path: directories for NAME.ngc subroutine files; empty: the program's own
    /// directory.
    std::vector<std::string> gcode_subroutine_path;
    double gcode_z_down = 0.0;              ///< pen down when Z <= this (mm)
    std::vector<std::string> gcode_ignore;  ///< --ignore-code: more G/M codes to skip
    double tolerance = 0.01;                ///< mm, arcs to cubics (SVG, G-code)
    PlacementOptions placement;  ///< --rotate, --flip-y, --scale, --fit, ... (placement.hpp)
    std::string translate;       ///< --translate "X,Y" (mm), parsed by load_path
    bool keep_order = false;     ///< --keep-order: draw the subpaths as the file lists them
    bool order = false;          ///< --order: reorder where the default keeps the file's order
    /// The command keeps the file's order and direction unless --order (eval, setpoints: they
    /// show the file's spans). G-code files keep the program's order unless --order, whatever
    /// the command: reversing a cut flips climb and conventional milling.
    bool keep_order_by_default = false;
    double merge_tolerance = 0.01;    ///< --merge-tolerance: mm between ends that are joined
    std::string order_start;          ///< --order-start "X,Y,..." (mm); empty: the origin
    std::vector<std::string> layers;  ///< --layer NAME|N (repeatable): plot only these layers
    std::string pause = "pen";  ///< --pause: pen (between layers with other pens), layer, none
};

/// A loaded path and what placement and ordering did to it (for check).
struct LoadedPath {
    Path path;
    PlacementReport placement;
    bool placed = false;  ///< a placement option was given
    OrderReport order;
    bool ordered = false;  ///< ordering ran (not --keep-order)
    /// Why the file's order was kept when it was: "--keep-order", "G-code keeps the program's
    /// order", "this command keeps the file's order"; empty when ordered.
    std::string kept_order_because;
    std::string gcode_pen;  ///< G-code files: the pen mode used and why; empty otherwise
};

/// Reads the path: .json, .csv, .svg, .gcode/.ngc/.nc/.gc by extension, then places it and
/// orders its subpaths (unless keep_order). `machine` (optional): its work area serves --fit
/// area. `start` (optional, mm per axis): where the pen is before the path, when
/// --order-start does not say. Throws InputError for bad files, std::invalid_argument for bad
/// placement or order options.
LoadedPath load_path_report(const JobRequest& request, const MachineProfile* machine = nullptr,
                            const std::vector<double>* start = nullptr);

/// load_path_report's path alone.
Path load_path(const JobRequest& request, const MachineProfile* machine = nullptr,
               const std::vector<double>* start = nullptr);

/// The path file's bytes (standard input for "-") and its format: --format, else the file's
/// extension, else (standard input) what its first characters say ("json", "csv", "svg",
/// "gcode"; "" for empty standard input). Throws InputError for an unknown extension or a file
/// that cannot be read.
std::string read_path_input(const JobRequest& request, std::string& format);

/// How messages name the path file: "<stdin>" for "-", else the file name.
inline std::string path_display_name(const std::string& file) {
    return file == "-" ? "<stdin>" : file;
}

}  // namespace pathstream::host
