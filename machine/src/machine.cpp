#include "pathstream/machine/machine.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/hal/modbus_target.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/json_document.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {
namespace {

// A JSON object key as a JSON pointer token (RFC 6901: ~ as ~0, / as ~1).
std::string json_pointer_token(const std::string& key) {
    std::string out;
    for (const char c : key)
        out += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
    return out;
}

using nlohmann::json;

class ProfileReader : public JsonChecker {
public:
    using JsonChecker::JsonChecker;

    /// A finite number in [lo, hi] (inclusive), or exclusive of lo when lo_open.
    double number(const json& v, const std::string& pointer, const std::string& what, double lo,
                  double hi, bool lo_open, const char* unit) const {
        if (!v.is_number()) fail(pointer, what + " must be a number");
        const double x = v.get<double>();
        if (!std::isfinite(x)) fail(pointer, what + " is not finite");
        if ((lo_open ? x <= lo : x < lo) || x > hi) {
            std::ostringstream m;
            m << what << " " << x << " " << unit
              << " is impossible (allowed: " << (lo_open ? "> " : ">= ") << lo << " and <= " << hi
              << " " << unit << ")";
            fail(pointer, m.str());
        }
        return x;
    }

    MachineProfile read(const json& root) const {
        if (!root.is_object()) fail("", "a machine profile must be a JSON object");
        only_keys(root, "",
                  {"axes", "mm_per_lsb", "tick_hz", "ticks_per_span", "feed", "travel_feed",
                   "pen_down_delay", "pen_up_delay", "chord_tolerance", "corner_stop_angle", "gpio",
                   "layer_feeds", "spindle", "output_coils", "input_shaper", "resonance",
                   "plan_for_shaper"});
        MachineProfile p;
        if (!root.contains("axes")) fail("", "machine profile has no \"axes\"");
        const json& axes = root["axes"];
        if (!axes.is_array() || axes.empty() || axes.size() > 8)
            fail("/axes", "axes must be an array of 1 to 8 axis objects");
        for (std::size_t i = 0; i < axes.size(); ++i) {
            const std::string ptr = "/axes/" + std::to_string(i);
            const json& a = axes[i];
            if (!a.is_object())
                fail(ptr, "axis must be an object with name, max_velocity, max_acceleration");
            only_keys(a, ptr, {"name", "max_velocity", "max_acceleration", "max_jerk", "travel"});
            for (const char* key : {"name", "max_velocity", "max_acceleration"}) {
                if (!a.contains(key)) fail(ptr, std::string("axis has no \"") + key + "\"");
            }
            AxisLimits limits;
            if (!a["name"].is_string() || a["name"].get<std::string>().empty())
                fail(ptr + "/name", "axis name must be a non-empty string");
            limits.name = a["name"].get<std::string>();
            for (const auto& other : p.axes) {
                if (other.name == limits.name)
                    fail(ptr + "/name", "axis name \"" + limits.name + "\" is used twice");
            }
            limits.max_velocity = number(a["max_velocity"], ptr + "/max_velocity", "max_velocity",
                                         0, 1e5, true, "mm/s");
            limits.max_acceleration = number(a["max_acceleration"], ptr + "/max_acceleration",
                                             "max_acceleration", 0, 1e7, true, "mm/s^2");
            if (a.contains("max_jerk")) {
                limits.max_jerk =
                    number(a["max_jerk"], ptr + "/max_jerk", "max_jerk", 0, 1e10, true, "mm/s^3");
            }
            if (a.contains("travel")) {
                const json& t = a["travel"];
                if (!t.is_array() || t.size() != 2)
                    fail(ptr + "/travel", "travel must be [min, max] in mm");
                limits.travel_min =
                    number(t[0], ptr + "/travel/0", "travel min", -1e5, 1e5, false, "mm");
                limits.travel_max =
                    number(t[1], ptr + "/travel/1", "travel max", -1e5, 1e5, false, "mm");
                if (limits.travel_max <= limits.travel_min) {
                    fail(ptr + "/travel", "travel max must be above travel min");
                }
                limits.has_travel = true;
            }
            p.axes.push_back(limits);
        }
        if (root.contains("mm_per_lsb"))
            p.mm_per_lsb =
                number(root["mm_per_lsb"], "/mm_per_lsb", "mm_per_lsb", 1e-6, 10, false, "mm");
        if (root.contains("tick_hz")) {
            // The device's own range: a profile never asks for a rate the device refuses.
            p.tick_hz = number(root["tick_hz"], "/tick_hz", "tick_hz", device::kMinTickHz,
                               device::kMaxTickHz, false, "Hz");
        }
        if (root.contains("ticks_per_span")) {
            const json& v = root["ticks_per_span"];
            if (!v.is_number_integer())
                fail("/ticks_per_span", "ticks_per_span must be a whole number");
            const double n =
                number(v, "/ticks_per_span", "ticks_per_span", 1, kMaxSpanTicks, false, "ticks");
            p.ticks_per_span = static_cast<std::uint32_t>(n);
        }
        if (root.contains("feed"))
            p.feed = number(root["feed"], "/feed", "feed", 0, 1e5, true, "mm/s");
        if (root.contains("travel_feed"))
            p.travel_feed =
                number(root["travel_feed"], "/travel_feed", "travel_feed", 0, 1e5, true, "mm/s");
        if (root.contains("pen_down_delay"))
            p.pen_down_delay = number(root["pen_down_delay"], "/pen_down_delay", "pen_down_delay",
                                      0, 60, false, "s");
        if (root.contains("pen_up_delay"))
            p.pen_up_delay =
                number(root["pen_up_delay"], "/pen_up_delay", "pen_up_delay", 0, 60, false, "s");
        if (root.contains("chord_tolerance")) {
            p.chord_tolerance = number(root["chord_tolerance"], "/chord_tolerance",
                                       "chord_tolerance", 0, 10, true, "mm");
        }
        if (root.contains("corner_stop_angle")) {
            // Degrees, as CAM tools give angles. Not below 1: joints of smooth curves turn by
            // rounding noise, and each would become a stop.
            const double degrees = number(root["corner_stop_angle"], "/corner_stop_angle",
                                          "corner_stop_angle", 1, 180, false, "degrees");
            p.corner_stop_angle = degrees * 3.14159265358979323846 / 180;
        }
        // One LSB cannot be resolved more finely than the tolerance asks for: a tolerance below
        // half an LSB could never be met by integer setpoints.
        if (p.chord_tolerance < p.mm_per_lsb / 2) {
            std::ostringstream m;
            m << "chord_tolerance " << p.chord_tolerance << " mm is below half an LSB ("
              << p.mm_per_lsb / 2 << " mm): integer setpoints cannot meet it";
            fail(root.contains("chord_tolerance") ? "/chord_tolerance" : "/mm_per_lsb", m.str());
        }
        check_plannable(root, p);
        if (root.contains("gpio")) p.gpio = gpio(root["gpio"], p);
        if (root.contains("spindle")) p.spindle = spindle(root["spindle"]);
        if (root.contains("output_coils")) p.output_coils = output_coils(root["output_coils"]);
        p.input_shaper.assign(p.axes.size(), std::nullopt);
        if (root.contains("input_shaper")) input_shaper(root["input_shaper"], p);
        if (root.contains("plan_for_shaper")) {
            if (!root["plan_for_shaper"].is_boolean())
                fail("/plan_for_shaper", "plan_for_shaper must be true or false");
            p.plan_for_shaper = root["plan_for_shaper"].get<bool>();
            bool any = false;
            for (const auto& s : p.input_shaper) any = any || s.has_value();
            if (p.plan_for_shaper && !any)
                fail("/plan_for_shaper", "plan_for_shaper needs an \"input_shaper\" to plan for");
        }
        if (root.contains("resonance")) p.resonance = resonance(root["resonance"], p);
        if (root.contains("layer_feeds")) {
            const json& f = root["layer_feeds"];
            if (!f.is_object())
                fail("/layer_feeds",
                     "layer_feeds must be an object like {\"red\": 20} (mm/s per layer)");
            for (const auto& [name, value] : f.items()) {
                const std::string ptr = "/layer_feeds/" + json_pointer_token(name);
                p.layer_feeds.emplace_back(name,
                                           number(value, ptr, "layer feed", 0, 1e5, true, "mm/s"));
                if (p.layer_feeds.back().second < min_velocity(p)) {
                    fail(ptr, "layer feed " + format(p.layer_feeds.back().second) +
                                  " mm/s is below " + min_velocity_reason(p) +
                                  " (allowed: >= " + format(min_velocity(p)) + " mm/s)");
                }
            }
        }
        return p;
    }

private:
    // Values the planner cannot work with although each is within its own range: speeds and
    // accelerations too small for the position and time grid (a span moves whole LSB at its
    // ends), spans so long that one at full speed crosses the whole work area. Each is
    // refused at the value that decides it, with the range it must lie in.
    void check_plannable(const json& root, const MachineProfile& p) const {
        const double n = p.ticks_per_span;
        const double v_min = min_velocity(p);
        const double a_min = min_acceleration(p);
        const std::string grid = "(" + format(p.mm_per_lsb) + " mm/LSB, " + format(p.tick_hz) +
                                 " Hz, " + format(n) + " ticks per span)";
        const std::string floor = v_min > kSlowestVelocity
                                      ? "1 LSB per span " + grid + ": planning would crawl"
                                      : min_velocity_reason(p);
        for (std::size_t i = 0; i < p.axes.size(); ++i) {
            const AxisLimits& a = p.axes[i];
            const std::string ptr = "/axes/" + std::to_string(i);
            if (a.max_velocity < v_min) {
                fail(ptr + "/max_velocity",
                     "max_velocity " + format(a.max_velocity) + " mm/s is below " + floor +
                         " (allowed: >= " + format(v_min) + " mm/s" +
                         (v_min > kSlowestVelocity ? "; or raise ticks_per_span, or lower tick_hz)"
                                                   : ")"));
            }
            if (a.max_acceleration < a_min) {
                fail(ptr + "/max_acceleration",
                     "max_acceleration " + format(a.max_acceleration) +
                         " mm/s^2 cannot gain 1 LSB per span of speed within one span " + grid +
                         " (allowed: >= " + format(a_min) +
                         " mm/s^2; or raise ticks_per_span, or lower tick_hz)");
            }
            // One span at the axis's top speed must stay within its travel, or within the
            // device's position range when it has none.
            const double extent = a.has_travel
                                      ? a.travel_max - a.travel_min
                                      : 2.0 * static_cast<double>(kMaxPositionLsb) * p.mm_per_lsb;
            const double span_mm = a.max_velocity * n / p.tick_hz;
            if (span_mm > extent) {
                const double longest =
                    std::max(1.0, std::floor(extent * p.tick_hz / a.max_velocity));
                const std::string where =
                    a.has_travel ? "its travel" : "the device's position range";
                const std::string what = "a span of " + format(n) + " ticks at axis " + a.name +
                                         "'s max_velocity " + format(a.max_velocity) +
                                         " mm/s crosses " + format(span_mm) + " mm, more than " +
                                         where + " (" + format(extent) + " mm)";
                if (root.contains("ticks_per_span")) {
                    fail("/ticks_per_span", "ticks_per_span " + format(n) +
                                                " is too long: " + what + " (allowed: 1 .. " +
                                                format(longest) + " ticks)");
                }
                fail(ptr + "/max_velocity",
                     "max_velocity " + format(a.max_velocity) + " mm/s is too fast for " +
                         "spans of " + format(n) + " ticks: " + what +
                         " (allowed: <= " + format(extent * p.tick_hz / n) + " mm/s)");
            }
        }
        // Without a travel, the position range bounds a span only at hundreds of metres: a span
        // may then last no longer than each such axis's stop from its max_velocity at its
        // max_acceleration (v / a), or the default span, or the shortest span the floors above
        // allow for it, whichever is longest. Longer spans make every stop of the path cost a
        // whole span (65,536 ticks: 65.5 s at 1 kHz) and plan for minutes.
        for (std::size_t i = 0; i < p.axes.size(); ++i) {
            const AxisLimits& a = p.axes[i];
            if (a.has_travel) continue;
            const double stop_ticks = a.max_velocity * p.tick_hz / a.max_acceleration;
            const double floor_ticks =
                std::max(p.mm_per_lsb * p.tick_hz / a.max_velocity,
                         p.tick_hz * std::sqrt(p.mm_per_lsb / a.max_acceleration));
            const double longest = std::max({std::floor(stop_ticks),
                                             static_cast<double>(MachineProfile{}.ticks_per_span),
                                             std::ceil(floor_ticks)});
            if (n <= longest) continue;
            fail(root.contains("ticks_per_span") ? "/ticks_per_span" : "",
                 "ticks_per_span " + format(n) + " is too long: a span of " + format(n) +
                     " ticks (" + format(n / p.tick_hz) + " s) outlasts axis " + a.name +
                     "'s stop from its max_velocity " + format(a.max_velocity) +
                     " mm/s at its max_acceleration " + format(a.max_acceleration) + " mm/s^2 (" +
                     format(stop_ticks / p.tick_hz) +
                     " s), and the axis has no travel to bound it " + "(allowed: 1 .. " +
                     format(longest) + " ticks)");
        }
        const auto check_feed = [&](const char* key, double feed) {
            if (feed >= v_min) return;
            const bool given = root.contains(key);
            fail(given ? std::string("/") + key : std::string(),
                 std::string(key) + (given ? " " : " (default) ") + format(feed) +
                     " mm/s is below " + floor + " (allowed: >= " + format(v_min) + " mm/s)");
        };
        check_feed("feed", p.feed);
        check_feed("travel_feed", p.travel_feed);
    }

    // Shortest decimal that reads back as `x` (up to 6 significant digits).
    static std::string format(double x) {
        std::ostringstream m;
        m << x;
        return m.str();
    }

    GpioLineConfig line(const json& v, const std::string& ptr, const char* what) const {
        if (!v.is_object()) fail(ptr, std::string(what) + " must be an object like {\"line\": 3}");
        only_keys(v, ptr, {"line", "active_low", "bias"});
        if (!v.contains("line")) fail(ptr, std::string(what) + " has no \"line\"");
        GpioLineConfig c;
        const json& l = v["line"];
        if (l.is_number_integer()) {
            if (l.get<long long>() < 0 || l.get<long long>() > 65535)
                fail(ptr + "/line", "line offset must be 0..65535");
            c.line = std::to_string(l.get<long long>());
        } else if (l.is_string() && !l.get<std::string>().empty()) {
            c.line = l.get<std::string>();
        } else {
            fail(ptr + "/line", "line must be an offset (whole number) or a line name (string)");
        }
        if (v.contains("active_low")) {
            if (!v["active_low"].is_boolean())
                fail(ptr + "/active_low", "active_low must be true or false");
            c.active_low = v["active_low"].get<bool>();
        }
        if (v.contains("bias")) {
            const json& b = v["bias"];
            const std::set<std::string> biases{"as-is", "disable", "pull-up", "pull-down"};
            if (!b.is_string() || biases.count(b.get<std::string>()) == 0) {
                fail(ptr + "/bias", "bias must be one of: as-is, disable, pull-up, pull-down");
            }
            c.bias = b.get<std::string>();
        }
        return c;
    }

    /// "input_shaper": {"x": {"type": "mzv", "frequency": 40, "damping": 0.1}, ...}, each
    /// axis's shaper checked against the device's history at the profile's tick rate.
    void input_shaper(const json& v, MachineProfile& p) const {
        if (!v.is_object()) {
            fail("/input_shaper",
                 "input_shaper must be an object like {\"x\": {\"type\": "
                 "\"mzv\", \"frequency\": 40}}");
        }
        for (const auto& [name, s] : v.items()) {
            const std::string ptr = "/input_shaper/" + json_pointer_token(name);
            std::size_t axis = p.axes.size();
            for (std::size_t a = 0; a < p.axes.size(); ++a)
                if (p.axes[a].name == name) axis = a;
            if (axis == p.axes.size()) fail(ptr, "the profile has no axis \"" + name + "\"");
            if (!s.is_object())
                fail(ptr, "an axis's shaper must be an object with type and frequency");
            only_keys(s, ptr, {"type", "frequency", "damping"});
            if (!s.contains("type") || !s["type"].is_string())
                fail(ptr, "the shaper needs a \"type\": one of " + shaper_type_names());
            const auto type = shaper_type_from_name(s["type"].get<std::string>());
            if (!type) {
                fail(ptr + "/type", "unknown shaper type \"" + s["type"].get<std::string>() +
                                        "\" (known: " + shaper_type_names() + ")");
            }
            if (!s.contains("frequency")) fail(ptr, "the shaper needs a \"frequency\" in Hz");
            ShaperSpec spec;
            spec.type = *type;
            spec.frequency_hz =
                number(s["frequency"], ptr + "/frequency", "frequency", 0, 1e4, true, "Hz");
            if (s.contains("damping")) {
                spec.damping =
                    number(s["damping"], ptr + "/damping", "damping", 0, 0.99, false, "");
            }
            try {
                (void)design_shaper_taps(spec, p.tick_hz, kDeviceShaperHistoryTicks);
            } catch (const std::invalid_argument& e) {
                fail(ptr + "/frequency", e.what());
            }
            p.input_shaper[axis] = spec;
        }
    }

    // "resonance": {"x": [{"frequency": 40, "damping": 0.05}, ...], ...} by axis name.
    std::vector<std::vector<ResonanceMode>> resonance(const json& v,
                                                      const MachineProfile& p) const {
        const char* example = "{\"x\": [{\"frequency\": 40, \"damping\": 0.05}]}";
        if (!v.is_object())
            fail("/resonance", std::string("resonance must be an object like ") + example);
        std::set<std::string> names;
        for (const auto& a : p.axes) names.insert(a.name);
        only_keys(v, "/resonance", names);
        std::vector<std::vector<ResonanceMode>> modes(p.axes.size());
        for (std::size_t axis = 0; axis < p.axes.size(); ++axis) {
            const std::string& name = p.axes[axis].name;
            if (!v.contains(name)) continue;
            const std::string ptr = "/resonance/" + json_pointer_token(name);
            const json& list = v[name];
            if (!list.is_array() || list.empty() || list.size() > kMaxResonanceModes) {
                fail(ptr, "axis " + name + "'s resonance must be an array of 1 to " +
                              std::to_string(kMaxResonanceModes) +
                              " modes like [{\"frequency\": 40, \"damping\": 0.05}]");
            }
            for (std::size_t i = 0; i < list.size(); ++i) {
                const std::string mode_ptr = ptr + "/" + std::to_string(i);
                modes[axis].push_back(resonance_mode(list[i], mode_ptr, p.tick_hz));
            }
        }
        return modes;
    }

    ResonanceMode resonance_mode(const json& m, const std::string& ptr, double tick_hz) const {
        if (!m.is_object())
            fail(ptr, "a mode must be an object like {\"frequency\": 40, \"damping\": 0.05}");
        only_keys(m, ptr, {"frequency", "damping"});
        for (const char* key : {"frequency", "damping"})
            if (!m.contains(key)) fail(ptr, std::string("mode has no \"") + key + "\"");
        ResonanceMode mode;
        // Below the Nyquist frequency: a faster mode cannot show in positions sampled per tick.
        mode.frequency_hz =
            number(m["frequency"], ptr + "/frequency", "frequency", 0, 1e6, true, "Hz");
        if (mode.frequency_hz >= tick_hz / 2) {
            fail(ptr + "/frequency", "frequency " + format(mode.frequency_hz) +
                                         " Hz is impossible (allowed: > 0 and below half the "
                                         "tick rate, " +
                                         format(tick_hz / 2) + " Hz)");
        }
        mode.damping = number(m["damping"], ptr + "/damping", "damping", 0, 1, true, "(ratio)");
        return mode;
    }

    SpindleConfig spindle(const json& v) const {
        if (!v.is_object()) fail("/spindle", "spindle must be an object like {\"spin_up\": 2}");
        only_keys(v, "/spindle", {"spin_up"});
        SpindleConfig c;
        c.present = true;
        if (v.contains("spin_up"))
            c.spin_up = number(v["spin_up"], "/spindle/spin_up", "spin_up", 0, 600, false, "s");
        return c;
    }

    OutputCoilsConfig output_coils(const json& v) const {
        if (!v.is_object()) {
            fail("/output_coils",
                 "output_coils must be an object like {\"target\": "
                 "\"modbus-tcp://HOST:PORT?unit=1\", \"spindle\": 0}");
        }
        std::set<std::string> keys{"target"};
        for (const char* key : kMachineFunctionKeys) keys.insert(key);
        only_keys(v, "/output_coils", keys);
        OutputCoilsConfig c;
        c.present = true;
        if (!v.contains("target")) fail("/output_coils", "output_coils has no \"target\"");
        const json& t = v["target"];
        if (!t.is_string())
            fail("/output_coils/target",
                 "target must be a Modbus URL string (modbus-tcp://HOST:PORT?unit=N or "
                 "modbus-rtu://DEVICE?baud=B&unit=N)");
        c.target = t.get<std::string>();
        hal::ModbusTarget target;
        try {
            target = hal::parse_modbus_target(c.target);
        } catch (const std::invalid_argument& e) {
            fail("/output_coils/target", e.what());
        }
        // Unit 0 on a serial line is a broadcast: nobody answers, so no write is confirmed and
        // a module that is gone would never stop the machine.
        if (target.transport == hal::ModbusTarget::Transport::kRtu && target.unit == 0)
            fail("/output_coils/target",
                 "unit 0 is the broadcast address: no answer would confirm a write (give the "
                 "module's unit, 1..247)");
        bool any = false;
        for (unsigned k = 0; k < kMachineFunctionCount; ++k) {
            const char* key = kMachineFunctionKeys[k];
            if (!v.contains(key)) continue;
            const std::string ptr = std::string("/output_coils/") + key;
            const json& a = v[key];
            if (!a.is_number_integer() || a.get<long long>() < 0 || a.get<long long>() > 65535)
                fail(ptr, std::string(key) + " coil address must be a whole number 0..65535");
            c.coil[k] = static_cast<std::int32_t>(a.get<long long>());
            for (unsigned j = 0; j < k; ++j) {
                if (c.coil[j] == c.coil[k])
                    fail(ptr, "coil " + std::to_string(c.coil[k]) + " is " +
                                  kMachineFunctionKeys[j] + "'s already: one coil per function");
            }
            any = true;
        }
        if (!any)
            fail("/output_coils",
                 "output_coils switches no function: give a coil for one or more of spindle, "
                 "spindle_reverse, mist, flood");
        return c;
    }

    GpioConfig gpio(const json& g, const MachineProfile& p) const {
        if (!g.is_object()) fail("/gpio", "gpio must be an object");
        only_keys(g, "/gpio",
                  {"chip", "enable", "estop", "pen", "spindle", "spindle_reverse", "mist", "flood",
                   "limits", "home"});
        GpioConfig c;
        c.present = true;
        if (!g.contains("chip")) fail("/gpio", "gpio has no \"chip\"");
        if (!g["chip"].is_string() || g["chip"].get<std::string>().empty()) {
            fail("/gpio/chip",
                 "chip must be a chip name, path, number or label (non-empty string)");
        }
        c.chip = g["chip"].get<std::string>();
        if (g.contains("enable"))
            c.enable = line(g["enable"], "/gpio/enable", "enable"), c.has_enable = true;
        if (g.contains("estop"))
            c.estop = line(g["estop"], "/gpio/estop", "estop"), c.has_estop = true;
        if (g.contains("pen")) c.pen = line(g["pen"], "/gpio/pen", "pen"), c.has_pen = true;
        for (unsigned k = 0; k < kMachineFunctionCount; ++k) {
            const char* key = kMachineFunctionKeys[k];
            if (!g.contains(key)) continue;
            c.function[k] = line(g[key], std::string("/gpio/") + key, key);
            c.has_function[k] = true;
        }
        std::set<std::string> switch_names;
        for (const auto& a : p.axes) {
            switch_names.insert(a.name + "-");
            switch_names.insert(a.name + "+");
        }
        if (g.contains("limits")) {
            const json& lim = g["limits"];
            if (!lim.is_object())
                fail("/gpio/limits", "limits must be an object like {\"x-\": {\"line\": 3}}");
            only_keys(lim, "/gpio/limits", switch_names);
            for (auto it = lim.begin(); it != lim.end(); ++it) {
                c.limits.emplace_back(it.key(),
                                      line(it.value(), "/gpio/limits/" + it.key(), "limit switch"));
            }
        }
        if (g.contains("home")) {
            const json& home = g["home"];
            if (!home.is_object())
                fail("/gpio/home",
                     "home must be an object like {\"x\": {\"switch\": \"x-\", ...}}");
            std::set<std::string> axis_names;
            for (const auto& a : p.axes) axis_names.insert(a.name);
            only_keys(home, "/gpio/home", axis_names);
            for (auto it = home.begin(); it != home.end(); ++it) {
                const std::string ptr = "/gpio/home/" + it.key();
                const json& h = it.value();
                if (!h.is_object())
                    fail(ptr,
                         "homing must be an object with switch, search_velocity, "
                         "latch_velocity, "
                         "backoff, max_travel");
                only_keys(h, ptr,
                          {"switch", "search_velocity", "latch_velocity", "backoff", "max_travel",
                           "position", "pull_off"});
                for (const char* key :
                     {"switch", "search_velocity", "latch_velocity", "backoff", "max_travel"}) {
                    if (!h.contains(key)) fail(ptr, std::string("homing has no \"") + key + "\"");
                }
                HomingAxisConfig hc;
                hc.axis = it.key();
                const AxisLimits* axis = nullptr;
                for (const auto& a : p.axes) {
                    if (a.name == hc.axis) axis = &a;
                }
                const json& sw = h["switch"];
                if (!sw.is_string() || (sw.get<std::string>() != hc.axis + "-" &&
                                        sw.get<std::string>() != hc.axis + "+")) {
                    fail(ptr + "/switch",
                         "switch must be \"" + hc.axis + "-\" or \"" + hc.axis + "+\"");
                }
                hc.switch_name = sw.get<std::string>();
                bool fitted = false;
                for (const auto& l : c.limits) fitted = fitted || l.first == hc.switch_name;
                if (!fitted)
                    fail(ptr + "/switch",
                         "switch \"" + hc.switch_name + "\" is not in gpio.limits");
                hc.search_velocity = number(h["search_velocity"], ptr + "/search_velocity",
                                            "search_velocity", 0, axis->max_velocity, true, "mm/s");
                hc.latch_velocity = number(h["latch_velocity"], ptr + "/latch_velocity",
                                           "latch_velocity", 0, hc.search_velocity, true, "mm/s");
                hc.backoff = number(h["backoff"], ptr + "/backoff", "backoff", 0, 1e4, true, "mm");
                hc.max_travel =
                    number(h["max_travel"], ptr + "/max_travel", "max_travel", 0, 1e5, true, "mm");
                hc.pull_off = h.contains("pull_off") ? number(h["pull_off"], ptr + "/pull_off",
                                                              "pull_off", 0, 1e4, false, "mm")
                                                     : hc.backoff;
                if (h.contains("position"))
                    hc.position = number(h["position"], ptr + "/position", "position", -1e5, 1e5,
                                         false, "mm");
                c.home.push_back(hc);
            }
        }
        return c;
    }
};

}  // namespace

namespace {
double grid_velocity(const MachineProfile& p) {
    return p.mm_per_lsb * p.tick_hz / p.ticks_per_span;
}

}  // namespace

double min_velocity(const MachineProfile& p) {
    return std::max(grid_velocity(p), kSlowestVelocity);
}

std::string min_velocity_reason(const MachineProfile& p) {
    if (grid_velocity(p) >= kSlowestVelocity) return "1 LSB per span: planning would crawl";
    return "1 mm an hour: a drawing would plan and run for days";
}

double min_acceleration(const MachineProfile& p) {
    const double span_seconds = p.ticks_per_span / p.tick_hz;
    return grid_velocity(p) / span_seconds;
}

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

std::uint64_t delay_ticks(double seconds, double tick_hz) {
    if (!(seconds > 0)) return 0;
    return static_cast<std::uint64_t>(std::ceil(seconds * tick_hz - 1e-9));
}

}  // namespace pathstream::host
