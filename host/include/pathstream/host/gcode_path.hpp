// Reader of G-code (RS274/NGC as LinuxCNC reads it, the subset a pen plotter needs):
// docs/formats-gcode.md.
#pragma once

#include <string>
#include <vector>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// What lowers the pen.
enum class PenControl {
    kZ,        ///< down during feed moves (G1 G2 G3 G5 G5.1 G5.2) at Z <= z_down_max
    kSpindle,  ///< down during feed moves made between M3 (or M4) and M5
    kMotion,   ///< down during every feed move: G1 draws, G0 travels (files with no pen codes)
    kAuto,     ///< one of the above, chosen from what the program does (GcodeReadInfo says why)
    /// A machine, not a pen: every move is made in the program's order, feed moves (G1 G2 G3
    /// G5 ...) as drawn subpaths, rapids (G0, G28, G30, canned cycle retracts) as travel
    /// subpaths (Subpath::travel) with every waypoint kept. Z is a motion axis when `axes` has
    /// it. The only mode for a machine with a Z axis; kAuto picks it there.
    kMachine,
};

/// "z", "spindle", "motion", "auto": the name the CLI uses.
const char* pen_control_name(PenControl pen);

/// How to read a G-code program.
/// What a program may cost before the read fails naming the line (docs/formats-gcode.md,
/// "Budgets"): bounds the time and memory of a hostile program. The defaults are the reader's;
/// smaller ones suit a fuzzer or a service that reads untrusted programs.
struct GcodeBudget {
    std::size_t blocks = 10'000'000;       ///< lines run, loops counted each pass
    std::size_t characters = 500'000'000;  ///< characters of the lines run
    std::size_t loop_passes = 1'000'000;   ///< loop passes in all
    std::size_t pieces = 2'000'000;        ///< curve pieces drawn (about 170 bytes each)
};

struct GcodeOptions {
    PenControl pen = PenControl::kZ;  ///< what lowers the pen
    double z_down_max = 0.0;          ///< kZ: highest Z (mm) at which the pen is down; finite
    double arc_tolerance_mm = 0.01;  ///< largest distance of an arc's Beziers from the arc; >= 1e-6
    /// G and M codes skipped with a warning, besides the default ones (M6, M7, ...):
    /// "M300", "G43", "m05" (case and leading zeros do not matter).
    std::vector<std::string> ignore_codes;
    /// The path's axes by G-code letter, in the machine profile's order: "XY" (a plotter: Z
    /// is the pen signal), "XYZ" (a router), "XYZA". Letters from XYZABCUVW, each once, X and Y
    /// among them. Axis words of letters not here are an error (Z: the pen signal).
    std::string axes = "XY";
    /// mm/s: the feed of rapids (G0) in kMachine mode, as high as the machine's axes allow so
    /// that each axis's own limit governs (the profile's fastest straight move); 0: the
    /// profile's travel_feed.
    double rapid_feed = 0;
    /// A LinuxCNC tool table file (G43 H reads it); empty: none (G43 H then fails).
    std::string tool_table;
    /// Directories searched, in order, for NAME.ngc when the program calls a subroutine it
    /// does not define (LinuxCNC's SUBROUTINE_PATH); empty: such a call is an error.
    std::vector<std::string> subroutine_path;
    GcodeBudget budget;  ///< what the program may cost; each value >= 1
};

/// What a read found beside the path.
struct GcodeReadInfo {
    PenControl pen = PenControl::kZ;  ///< the pen mode used (never kAuto)
    std::string pen_reason;           ///< why that mode, one line ("asked for", or the evidence)
    /// One per skipped code (and for grbl '$' lines), at its first use:
    /// "file:line:col: M6 skipped (...); later ones are skipped without a warning".
    std::vector<std::string> warnings;
};

/// Parses a G-code program into a path of options.axes (X, Y in mm for a plotter): one subpath
/// (basis kBezier, open, points P0 C C P1 C C ... of 3k + 1) per maximal run of pen-down moves with
/// one feed and one path control mode (G61, G61.1, G64 [P]: Subpath::corner_mode, blend_tolerance,
/// stops); G0 and pen-up moves are travel between subpaths. Subpath::feed is the F word in mm/s (0
/// until the program gives F). `file` names the source in error messages. Throws InputError
/// ("file:line:col: what is wrong") at the offending word for syntax errors, unsupported words and
/// codes, missing or repeated words, out-of-range numbers (> 1e6 mm) and impossible arcs; and
/// ("file: no pen-down moves ...") when nothing is drawn. Runs parameters, expressions and O-word
/// control flow as LinuxCNC does, within budgets. Throws std::invalid_argument when `options` is
/// out of range (also an ignore_codes entry that is no G or M code). When `info` is given it
/// receives the pen mode and the warnings.
Path parse_gcode_path(const std::string& text, const std::string& file,
                      const GcodeOptions& options = {}, GcodeReadInfo* info = nullptr);

/// Reads and parses a G-code file. Throws as parse_gcode_path, and InputError when the file
/// cannot be read.
Path load_gcode_path(const std::string& file, const GcodeOptions& options = {},
                     GcodeReadInfo* info = nullptr);

}  // namespace pathstream::host
