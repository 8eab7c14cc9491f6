// How every command reads its path file: by extension, with the per-format options.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

struct PathOptions {
    std::string file;
    std::string csv_basis = "bspline";  ///< basis for CSV point files
    bool csv_closed = false;
    std::string gcode_pen = "z";        ///< "z" or "spindle" (M3/M5)
    double gcode_z_down = 0.0;          ///< pen down when Z <= this (mm)
    double tolerance = 0.01;            ///< mm, arcs to cubics (SVG, G-code)
};

/// Adds the FILE argument and the format options to a subcommand.
void add_path_options(CLI::App& command, PathOptions& options);

/// Reads the path: .json, .csv, .svg, .gcode/.ngc/.nc/.gc by extension. Throws InputError.
Path load_path(const PathOptions& options);

/// Column names of the axes in CSV output: x y z a b c v w (u is taken by the parameter).
const char* axis_column_name(std::size_t axis);

/// Shortest decimal text that reads back as exactly `value` (round-trip), for CSV output.
std::string exact_decimal(double value);

}  // namespace pathstream::host
