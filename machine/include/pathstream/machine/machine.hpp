// The machine profile: what the axes can do and how the device ticks (docs/formats.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pathstream/machine/shaper_design.hpp"

namespace pathstream::host {

/// Limits of one axis, in millimetres and seconds.
struct AxisLimits {
    std::string name;             ///< "x", "y", ...
    double max_velocity = 0;      ///< mm/s, > 0
    double max_acceleration = 0;  ///< mm/s^2, > 0
    /// The work area along this axis ("travel": [min, max] in mm, min < max): a job whose path
    /// leaves it is refused, and the device checks every span against it. Absent: no limit.
    bool has_travel = false;
    double travel_min = 0, travel_max = 0;
    /// mm/s^3, > 0 when the profile sets "max_jerk"; 0: no jerk limit (acceleration may step
    /// at span joins as before).
    double max_jerk = 0;
};

/// One GPIO line of the profile's "gpio" object (docs/formats.md, docs/gpio.md).
struct GpioLineConfig {
    std::string line;            ///< offset ("3") or line name ("estop")
    bool active_low = false;     ///< active = electrically low
    std::string bias = "as-is";  ///< "as-is", "disable", "pull-up" or "pull-down"
};

/// Homing of one axis against one of its limit switches, in mm and mm/s.
struct HomingAxisConfig {
    std::string axis;            ///< axis name
    std::string switch_name;     ///< a key of GpioConfig::limits for this axis ("x-")
    double search_velocity = 0;  ///< > 0, <= the axis's max_velocity
    double latch_velocity = 0;   ///< > 0, <= search_velocity
    double backoff = 0;          ///< > 0
    double max_travel = 0;       ///< > 0
    double position = 0;         ///< coordinate of the switch point after homing
    /// Distance moved off the switch after zero is set (>= 0; default: backoff), so the
    /// machine ends homing off its switch.
    double pull_off = 0;
};

/// How many machine functions a profile can wire to an output of their own.
inline constexpr unsigned kMachineFunctionCount = 4;

/// The machine functions' keys in a profile's "gpio" and "output_coils" objects, in the order
/// of device::kMachineOutputBits (gpio_logic.hpp): spindle (on: M3/M4), spindle_reverse (on:
/// counter-clockwise, M4), mist (M7), flood (M8).
inline constexpr const char* kMachineFunctionKeys[kMachineFunctionCount] = {
    "spindle", "spindle_reverse", "mist", "flood"};

/// Which chip lines do what. Absent from the profile: present == false.
struct GpioConfig {
    bool present = false;
    std::string chip;  ///< "gpiochip0", "/dev/gpiochip0", a number or a chip label
    bool has_enable = false, has_estop = false, has_pen = false;
    GpioLineConfig enable;  ///< drive enable output
    GpioLineConfig estop;   ///< e-stop input
    GpioLineConfig pen;     ///< pen-lift output (active = pen down)
    /// Machine function outputs by kMachineFunctionKeys index (active = on, or counter-
    /// clockwise for spindle_reverse); has_function[k] says whether line k is fitted.
    bool has_function[kMachineFunctionCount] = {};
    GpioLineConfig function[kMachineFunctionCount];
    /// Limit switch inputs by "<axis><side>": "x-", "x+", "y-", ... (side "-" or "+").
    std::vector<std::pair<std::string, GpioLineConfig>> limits;
    std::vector<HomingAxisConfig> home;  ///< in profile order
};

/// The profile's optional "spindle" object: a spindle (or laser) switched by G-code M3/M4/M5
/// through the span outputs (kOutputSpindle, kOutputSpindleReverse).
struct SpindleConfig {
    bool present = false;
    /// Seconds the machine rests with the spindle on before it moves after M3 or M4 turn it on
    /// or reverse it, and before a resume re-enters a cut with it on (0..600).
    double spin_up = 0;
};

/// The profile's optional "output_coils" object: the machine functions switched by the coils
/// of a Modbus I/O module (a relay board, a VFD's run and direction inputs) that the device
/// writes as a client (docs/gpio.md, "Output coils").
struct OutputCoilsConfig {
    bool present = false;
    /// The module's URL, modbus-tcp://HOST:PORT?unit=N or modbus-rtu://DEVICE?...; it parses
    /// with hal::parse_modbus_target and its unit is not the broadcast address 0.
    std::string target;
    /// Coil address (0..65535) by kMachineFunctionKeys index; -1: the function has no coil.
    /// At least one is mapped, no two to the same coil.
    std::int32_t coil[kMachineFunctionCount] = {-1, -1, -1, -1};
};

/// One resonant mode of an axis's mechanics, from the profile's "resonance" object: what the
/// simulator's servo plant rings with (docs/simulator.md, "Resonant modes").
struct ResonanceMode {
    double frequency_hz = 0;  ///< natural frequency, > 0 and below tick_hz / 2
    double damping = 0;       ///< damping ratio, in (0, 1]
};

/// Most resonant modes one axis may have (profile or command line).
inline constexpr std::size_t kMaxResonanceModes = 4;

/// Everything the planner and the simulated device need to know about the machine.
struct MachineProfile {
    std::vector<AxisLimits> axes;      ///< one per path axis, in path order
    double mm_per_lsb = 0.001;         ///< position resolution
    double tick_hz = 1000;             ///< device tick rate
    std::uint32_t ticks_per_span = 8;  ///< span length the planner emits (device streaming unit)
    double feed = 50;                  ///< requested pen-down speed along the path, mm/s
    double travel_feed = 150;          ///< requested pen-up speed, mm/s
    double pen_down_delay = 0.05;      ///< s the pen needs to settle after going down
    double pen_up_delay = 0.05;        ///< s the pen needs to lift
    double chord_tolerance = 0.005;    ///< mm: max distance of executed ticks from the path
    /// Optional "corner_stop_angle" (1..180 degrees in the file, radians here): a joint turning
    /// by more stops exactly; absent (< 0): the planner's PlanOptions::corner_stop_angle.
    double corner_stop_angle = -1;
    GpioConfig gpio;                 ///< optional "gpio" object
    SpindleConfig spindle;           ///< optional "spindle" object
    OutputCoilsConfig output_coils;  ///< optional "output_coils" object
    /// Optional "input_shaper": per axis (path order, one entry per axis), the shaper the
    /// device applies to its setpoints, or none (docs/input-shaping.md).
    std::vector<std::optional<ShaperSpec>> input_shaper;
    /// Optional "plan_for_shaper": the planner slows bends and corners and rests at stops for
    /// the shapers' longest delay so that the device's shaped command stays on the path within
    /// the chord tolerance (docs/input-shaping.md); false: the plan is unshaped's, and plan and
    /// sim report how far the shaped command leaves the path.
    bool plan_for_shaper = false;
    /// Optional "layer_feeds": pen-down speed (mm/s) per layer name (an Inkscape layer's label,
    /// a stroke colour such as "#ff0000"), for subpaths that set no feed of their own.
    std::vector<std::pair<std::string, double>> layer_feeds;
    /// Optional "resonance": resonant modes per axis, in axis order, for the simulator. Empty
    /// without the key, else one list per axis (empty for an axis it does not name).
    std::vector<std::vector<ResonanceMode>> resonance;
    std::string source;  ///< file it came from, for messages

    double tick_seconds() const { return 1.0 / tick_hz; }
};

/// 1 mm an hour, mm/s: the slowest speed any profile may ask for. A drawing at that speed
/// already plans and runs for days (1 LSB per span on a fine grid can be slower still).
inline constexpr double kSlowestVelocity = 1.0 / 3600.0;

/// Slowest speed a profile may ask for, mm/s: 1 LSB per span (mm_per_lsb * tick_hz /
/// ticks_per_span; below it the spans' whole-LSB ends advance by less than one LSB per span
/// and planning crawls through ever more ticks), or kSlowestVelocity when that is faster. O(1).
double min_velocity(const MachineProfile& profile);
/// Which of the two floors min_velocity() is, and why, for messages. O(1).
std::string min_velocity_reason(const MachineProfile& profile);

/// Lowest max_acceleration a profile may give an axis, mm/s^2: the one that gains 1 LSB per
/// span of speed within one span (mm_per_lsb * tick_hz^2 / ticks_per_span^2). O(1).
double min_acceleration(const MachineProfile& profile);

/// Parses a machine profile JSON document. Throws InputError ("file:line:col: ...") on
/// malformed JSON, unknown keys, wrong types, non-finite or impossible values (zero or
/// negative limits, tick rate outside 10 Hz..100 kHz, ...), and on values the planner cannot
/// work with: a max_velocity, feed, travel_feed or layer feed below min_velocity(), a
/// max_acceleration below min_acceleration(), or spans so long that one at an axis's
/// max_velocity crosses more than its travel (or the device's position range without one).
MachineProfile parse_machine_profile(const std::string& text, const std::string& file);

/// Reads and parses a machine profile file. Throws InputError.
MachineProfile load_machine_profile(const std::string& file);

/// Ticks the planner dwells for a pen delay of `seconds`: ceil(seconds * tick_hz), ignoring
/// floating-point noise below 1e-9 tick. The device's pen-down delay comes from the same
/// rounding (device_setup.hpp), so it lives with the profile rather than with the planner.
std::uint64_t delay_ticks(double seconds, double tick_hz);

}  // namespace pathstream::host
