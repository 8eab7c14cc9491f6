// Loading a request's path: read by format, placed, split by layer, ordered.
#include "pathstream/host/job_request.hpp"

#include <cctype>
#include <charconv>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "pathstream/host/layers.hpp"
#include "pathstream/host/path_formats.hpp"

namespace pathstream::host {
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
        if (item.empty() || error != std::errc() || end != item.data() + item.size() ||
            !std::isfinite(v)) {
            throw std::invalid_argument(option + ": \"" + text +
                                        "\" is not a comma-separated list of numbers (mm)");
        }
        values.push_back(v);
        at = comma + 1;
    }
    return values;
}

}  // namespace

/// The G-code axis letters of a machine's axes ("XYZ" for axes named x, y, z), or "" when
/// its names are not all G-code axis letters with x and y among them.
std::string gcode_axes(const MachineProfile& machine) {
    std::string letters;
    for (const AxisLimits& a : machine.axes) {
        if (a.name.size() != 1) return "";
        const char c = static_cast<char>(std::toupper(static_cast<unsigned char>(a.name[0])));
        if (std::string("XYZABCUVW").find(c) == std::string::npos ||
            letters.find(c) != std::string::npos)
            return "";
        letters += c;
    }
    if (letters.find('X') == std::string::npos || letters.find('Y') == std::string::npos) return "";
    return letters;
}

LoadedPath load_path_report(const JobRequest& request, const MachineProfile* machine,
                            const std::vector<double>* start) {
    LoadedPath loaded;
    std::string format;
    JobRequest o = request;
    if (machine != nullptr && o.gcode_axes.empty()) {
        // A G-code program's axes are the machine's, by name; a machine whose names are no
        // axis letters reads X Y (a plotter's two axes).
        o.gcode_axes = gcode_axes(*machine);
        if (o.gcode_axes.empty()) o.gcode_axes = "XY";
        double fastest = 0;
        for (const AxisLimits& a : machine->axes) fastest += a.max_velocity * a.max_velocity;
        o.gcode_rapid_feed = std::sqrt(fastest);
    }
    Path path = read_request_path(o, loaded.gcode_pen, format);
    PlacementOptions placement = o.placement;
    if (machine != nullptr)
        placement.edge_clearance = machine->chord_tolerance + machine->mm_per_lsb;
    if (!o.translate.empty()) {
        const std::vector<double> xy = parse_numbers(o.translate, "--translate");
        if (xy.size() != 2)
            throw std::invalid_argument("--translate: give X,Y (2 numbers), got \"" + o.translate +
                                        "\"");
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
        for (const Subpath& s : path.subpaths) {
            if (s.travel) {
                throw std::invalid_argument(
                    "--order: this program's rapids are the machine's own moves (--gcode-pen "
                    "machine): its order is the machinist's and stays");
            }
        }
        OrderOptions order;
        order.merge_tolerance = o.merge_tolerance;
        if (!o.order_start.empty()) {
            order.start = parse_numbers(o.order_start, "--order-start");
            if (order.start.size() != path.axes) {
                throw std::invalid_argument("--order-start: give " + std::to_string(path.axes) +
                                            " coordinates (one per axis of the path), got \"" +
                                            o.order_start + "\"");
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

Path load_path(const JobRequest& o, const MachineProfile* machine,
               const std::vector<double>* start) {
    return load_path_report(o, machine, start).path;
}

}  // namespace pathstream::host
