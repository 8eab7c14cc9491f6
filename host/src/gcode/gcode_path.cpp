// parse_gcode_path / load_gcode_path: lines -> program run -> path; the pen mode choice.
#include "pathstream/host/gcode_path.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "interpreter.hpp"
#include "pathstream/machine/input_error.hpp"
#include "program.hpp"

namespace pathstream::host {

namespace {

// Lines without their LF or CR LF; views into `text`.
std::vector<std::string_view> split_lines(const std::string& text) {
    std::vector<std::string_view> lines;
    std::string_view rest(text);
    if (rest.substr(0, 3) == "\xEF\xBB\xBF") rest.remove_prefix(3);  // UTF-8 byte order mark
    lines.reserve(static_cast<std::size_t>(std::count(rest.begin(), rest.end(), '\n')) + 1);
    while (!rest.empty()) {
        const std::size_t end = rest.find('\n');
        std::string_view current = rest.substr(0, end);
        rest.remove_prefix(end == std::string_view::npos ? rest.size() : end + 1);
        if (!current.empty() && current.back() == '\r') current.remove_suffix(1);
        lines.push_back(current);
    }
    return lines;
}

// The shortest usual form of a length, for messages.
std::string mm_text(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// The mode the evidence of a run in Z mode points to, and why.
PenControl choose_pen(const gcode::PenEvidence& e, double z_down_max, std::string& reason) {
    const std::string z = "--gcode-z-down " + mm_text(z_down_max) + " mm";
    if (e.z_low && e.z_high) {
        reason = "auto: Z goes both above and to or below " + z;
        return PenControl::kZ;
    }
    if (e.spindle) {
        reason = "auto: M3/M4 appear and Z never crosses " + z;
        return PenControl::kSpindle;
    }
    reason = "auto: no M3/M4 and Z never crosses " + z + ", so G1 draws and G0 travels";
    return PenControl::kMotion;
}

// One run of the whole program in one pen mode.
Path run(const std::vector<std::string_view>& lines, const std::string& file,
         const GcodeOptions& options, const std::set<std::string>& ignored, bool allow_empty,
         gcode::PenEvidence* evidence, std::vector<std::string>& warnings,
         const gcode::ToolTable& tools) {
    gcode::Parameters parameters;
    gcode::Interpreter interpreter(file, options, parameters, tools);
    gcode::run_program(lines, file, ignored, interpreter, parameters, warnings, options.budget,
                       options.subroutine_path);
    if (evidence) *evidence = interpreter.evidence();
    return interpreter.finish(allow_empty);
}

// The axis letters a path may have: XYZABCUVW, each once, X and Y among them.
void check_axes(const std::string& axes) {
    const std::string letters = "XYZABCUVW";
    for (std::size_t i = 0; i < axes.size(); ++i) {
        if (letters.find(axes[i]) == std::string::npos || axes.find(axes[i]) != i) {
            throw std::invalid_argument("G-code axes \"" + axes +
                                        "\": each of X Y Z A B C U V W at most once");
        }
    }
    if (axes.find('X') == std::string::npos || axes.find('Y') == std::string::npos) {
        throw std::invalid_argument("G-code axes \"" + axes + "\" need X and Y");
    }
}

}  // namespace

const char* pen_control_name(PenControl pen) {
    switch (pen) {
        case PenControl::kZ:
            return "z";
        case PenControl::kSpindle:
            return "spindle";
        case PenControl::kMotion:
            return "motion";
        case PenControl::kAuto:
            return "auto";
        case PenControl::kMachine:
            return "machine";
    }
    return "?";
}

Path parse_gcode_path(const std::string& text, const std::string& file, const GcodeOptions& options,
                      GcodeReadInfo* info) {
    if (!std::isfinite(options.z_down_max)) {
        throw std::invalid_argument("GcodeOptions::z_down_max must be finite");
    }
    if (!(options.arc_tolerance_mm >= 1e-6) || !std::isfinite(options.arc_tolerance_mm)) {
        throw std::invalid_argument("GcodeOptions::arc_tolerance_mm must be finite and >= 1e-6");
    }
    check_axes(options.axes);
    if (!(options.rapid_feed >= 0) || !std::isfinite(options.rapid_feed)) {
        throw std::invalid_argument("GcodeOptions::rapid_feed must be finite and >= 0");
    }
    const GcodeBudget& b = options.budget;
    if (b.blocks == 0 || b.characters == 0 || b.loop_passes == 0 || b.pieces == 0) {
        throw std::invalid_argument("GcodeOptions::budget values must be >= 1");
    }
    const bool z_axis = options.axes.find('Z') != std::string::npos;
    if (z_axis && options.pen != PenControl::kMachine && options.pen != PenControl::kAuto) {
        throw std::invalid_argument(std::string("--gcode-pen ") + pen_control_name(options.pen) +
                                    ": Z is a motion axis " + "of this machine (axes " +
                                    options.axes +
                                    "), so moves are the machine's: use "
                                    "--gcode-pen machine (the default there)");
    }
    const gcode::ToolTable tools = options.tool_table.empty()
                                       ? gcode::ToolTable{}
                                       : gcode::ToolTable::load(options.tool_table);
    std::set<std::string> ignored = gcode::default_ignored_codes();
    for (const std::string& code : options.ignore_codes) {
        const auto name = gcode::normalise_code_name(code);
        if (!name) {
            throw std::invalid_argument("ignore code \"" + code +
                                        "\" is not a G or M code (like M300 or G43)");
        }
        ignored.insert(*name);
    }
    // On a machine M6 is a tool change: the job pauses for it unless asked to skip it.
    const bool m6_skip_asked =
        std::any_of(options.ignore_codes.begin(), options.ignore_codes.end(),
                    [](const std::string& c) { return gcode::normalise_code_name(c) == "M6"; });
    // And M7-M9 switch the coolant outputs, unless asked to skip them.
    const bool machine_codes = z_axis || options.pen == PenControl::kMachine;
    if (!m6_skip_asked && machine_codes) ignored.erase("M6");
    for (const char* code : {"M7", "M8", "M9"}) {
        const bool asked = std::any_of(
            options.ignore_codes.begin(), options.ignore_codes.end(),
            [&](const std::string& c) { return gcode::normalise_code_name(c) == code; });
        if (!asked && machine_codes) ignored.erase(code);
    }
    const std::vector<std::string_view> lines = split_lines(text);
    GcodeReadInfo local;
    GcodeReadInfo& out = info ? *info : local;
    out = {};
    GcodeOptions chosen = options;
    Path path;
    if (options.pen == PenControl::kAuto && z_axis) {
        chosen.pen = PenControl::kMachine;
        out.pen_reason = "auto: Z is a motion axis of this machine";
        path = run(lines, file, chosen, ignored, false, nullptr, out.warnings, tools);
    } else if (options.pen == PenControl::kAuto) {
        gcode::PenEvidence evidence;
        chosen.pen = PenControl::kZ;
        path = run(lines, file, chosen, ignored, true, &evidence, out.warnings, tools);
        chosen.pen = choose_pen(evidence, options.z_down_max, out.pen_reason);
        if (chosen.pen != PenControl::kZ || path.subpaths.empty()) {
            std::vector<std::string> again;  // the warnings of the first run stand
            path = Path{};                   // not held through the second run
            path = run(lines, file, chosen, ignored, false, nullptr, again, tools);
        }
    } else {
        out.pen_reason = "as asked";
        path = run(lines, file, chosen, ignored, false, nullptr, out.warnings, tools);
    }
    out.pen = chosen.pen;
    return path;
}

Path load_gcode_path(const std::string& file, const GcodeOptions& options, GcodeReadInfo* info) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return parse_gcode_path(buffer.str(), file, options, info);
}

}  // namespace pathstream::host
