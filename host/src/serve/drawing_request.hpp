// What the page may ask for a drawing: a file name the server stores it under and the path
// options (placement, layers, order), turned into the command-line arguments every path
// command reads, so the preview, the simulation and the stream parse them with the same code.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace pathstream::host::serve {

/// The name an upload is stored under in the server's own directory: the base name of
/// `name` with every character outside [A-Za-z0-9._-] replaced by '_', no leading dot, at
/// most 100 characters, and one of the path extensions (.json .csv .svg .gcode .ngc .nc .gc,
/// any case). Throws std::invalid_argument naming what is wrong.
std::string upload_file_name(const std::string& name);

/// Path options from the page's JSON object, as arguments after FILE: "fit" (area, a0..a6,
/// letter, legal, tabloid, optionally -landscape), "margin" (mm, 0..10000), "align",
/// "origin", "rotate" (0, 90, 180, 270), "flip_y", "keep_order", "layers" (names or numbers,
/// at most 256), "pause" (pen, layer, none), "gcode_pen" (z, spindle, motion, auto),
/// "csv_basis", "csv_closed". Unknown keys and values of the wrong kind throw
/// std::invalid_argument; values are checked again by the command-line parser they go to.
/// Every value is passed as --option=VALUE, so nothing the page sends can become an option
/// of its own.
std::vector<std::string> path_arguments(const nlohmann::json& options);

}  // namespace pathstream::host::serve
