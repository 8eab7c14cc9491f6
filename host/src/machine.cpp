#include "pathstream/host/machine.hpp"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "pathstream/host/input_error.hpp"
#include "pathstream/host/json_document.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {
namespace {

using nlohmann::json;

class ProfileReader : public JsonChecker {
public:
    using JsonChecker::JsonChecker;

    /// A finite number in [lo, hi] (inclusive), or exclusive of lo when lo_open.
    double number(const json& v, const std::string& pointer, const std::string& what, double lo, double hi,
                  bool lo_open, const char* unit) const {
        if (!v.is_number()) fail(pointer, what + " must be a number");
        const double x = v.get<double>();
        if (!std::isfinite(x)) fail(pointer, what + " is not finite");
        if ((lo_open ? x <= lo : x < lo) || x > hi) {
            std::ostringstream m;
            m << what << " " << x << " " << unit << " is impossible (allowed: " << (lo_open ? "> " : ">= ") << lo
              << " and <= " << hi << " " << unit << ")";
            fail(pointer, m.str());
        }
        return x;
    }

    MachineProfile read(const json& root) const {
        if (!root.is_object()) fail("", "a machine profile must be a JSON object");
        only_keys(root, "", {"axes", "mm_per_lsb", "tick_hz", "ticks_per_span", "feed", "travel_feed",
                             "pen_down_delay", "pen_up_delay", "chord_tolerance"});
        MachineProfile p;
        if (!root.contains("axes")) fail("", "machine profile has no \"axes\"");
        const json& axes = root["axes"];
        if (!axes.is_array() || axes.empty() || axes.size() > 8) fail("/axes", "axes must be an array of 1 to 8 axis objects");
        for (std::size_t i = 0; i < axes.size(); ++i) {
            const std::string ptr = "/axes/" + std::to_string(i);
            const json& a = axes[i];
            if (!a.is_object()) fail(ptr, "axis must be an object with name, max_velocity, max_acceleration");
            only_keys(a, ptr, {"name", "max_velocity", "max_acceleration"});
            for (const char* key : {"name", "max_velocity", "max_acceleration"}) {
                if (!a.contains(key)) fail(ptr, std::string("axis has no \"") + key + "\"");
            }
            AxisLimits limits;
            if (!a["name"].is_string() || a["name"].get<std::string>().empty()) fail(ptr + "/name", "axis name must be a non-empty string");
            limits.name = a["name"].get<std::string>();
            for (const auto& other : p.axes) {
                if (other.name == limits.name) fail(ptr + "/name", "axis name \"" + limits.name + "\" is used twice");
            }
            limits.max_velocity = number(a["max_velocity"], ptr + "/max_velocity", "max_velocity", 0, 1e5, true, "mm/s");
            limits.max_acceleration =
                number(a["max_acceleration"], ptr + "/max_acceleration", "max_acceleration", 0, 1e7, true, "mm/s^2");
            p.axes.push_back(limits);
        }
        if (root.contains("mm_per_lsb")) p.mm_per_lsb = number(root["mm_per_lsb"], "/mm_per_lsb", "mm_per_lsb", 1e-6, 10, false, "mm");
        if (root.contains("tick_hz")) p.tick_hz = number(root["tick_hz"], "/tick_hz", "tick_hz", 10, 100000, false, "Hz");
        if (root.contains("ticks_per_span")) {
            const json& v = root["ticks_per_span"];
            if (!v.is_number_integer()) fail("/ticks_per_span", "ticks_per_span must be a whole number");
            const double n = number(v, "/ticks_per_span", "ticks_per_span", 1, kMaxSpanTicks, false, "ticks");
            p.ticks_per_span = static_cast<std::uint32_t>(n);
        }
        if (root.contains("feed")) p.feed = number(root["feed"], "/feed", "feed", 0, 1e5, true, "mm/s");
        if (root.contains("travel_feed")) p.travel_feed = number(root["travel_feed"], "/travel_feed", "travel_feed", 0, 1e5, true, "mm/s");
        if (root.contains("pen_down_delay")) p.pen_down_delay = number(root["pen_down_delay"], "/pen_down_delay", "pen_down_delay", 0, 60, false, "s");
        if (root.contains("pen_up_delay")) p.pen_up_delay = number(root["pen_up_delay"], "/pen_up_delay", "pen_up_delay", 0, 60, false, "s");
        if (root.contains("chord_tolerance")) {
            p.chord_tolerance = number(root["chord_tolerance"], "/chord_tolerance", "chord_tolerance", 0, 10, true, "mm");
        }
        // One LSB cannot be resolved more finely than the tolerance asks for: a tolerance below
        // half an LSB could never be met by integer setpoints.
        if (p.chord_tolerance < p.mm_per_lsb / 2) {
            std::ostringstream m;
            m << "chord_tolerance " << p.chord_tolerance << " mm is below half an LSB (" << p.mm_per_lsb / 2
              << " mm): integer setpoints cannot meet it";
            fail(root.contains("chord_tolerance") ? "/chord_tolerance" : "/mm_per_lsb", m.str());
        }
        return p;
    }
};

}  // namespace

MachineProfile parse_machine_profile(const std::string& text, const std::string& file) {
    MachineProfile profile = ProfileReader(text, file).read(parse_json_document(text, file));
    profile.source = file;
    return profile;
}

MachineProfile load_machine_profile(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    return parse_machine_profile(buffer.str(), file);
}

}  // namespace pathstream::host
