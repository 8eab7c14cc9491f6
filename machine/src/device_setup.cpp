#include "pathstream/machine/device_setup.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "pathstream/machine/machine.hpp"

namespace pathstream::host {
namespace {

std::uint32_t fit_u32(double lsb, const std::string& what) {
    if (!(lsb >= 0) || lsb > 4294967295.0) {
        throw std::range_error(what + " (" + std::to_string(lsb) +
                               " LSB) does not fit the device's 32-bit values");
    }
    return static_cast<std::uint32_t>(lsb);
}

// Homing distances and velocities: the nearest LSB, at least one (a positive profile value
// never becomes a zero the sequencer would refuse).
std::uint32_t positive_lsb(double mm, double mm_per_lsb, const std::string& what) {
    const double v = std::round(mm / mm_per_lsb);
    return fit_u32(v < 1 ? 1 : v, what);
}

}  // namespace

DeviceLimitsLsb device_limits(const MachineProfile& profile) {
    DeviceLimitsLsb l;
    l.tick_hz = static_cast<std::uint32_t>(std::llround(profile.tick_hz));
    for (const AxisLimits& a : profile.axes) {
        // Rounded up: the planner works to the profile's limits exactly.
        l.max_velocity.push_back(fit_u32(std::ceil(a.max_velocity / profile.mm_per_lsb),
                                         "axis " + a.name + " max_velocity"));
        l.max_acceleration.push_back(fit_u32(std::ceil(a.max_acceleration / profile.mm_per_lsb),
                                             "axis " + a.name + " max_acceleration"));
        l.max_jerk.push_back(
            a.max_jerk > 0
                ? fit_u32(std::ceil(a.max_jerk / profile.mm_per_lsb / device::kJerkUnitLsb),
                          "axis " + a.name + " max_jerk (in 100 LSB/s^3)")
                : 0);
        const double range = static_cast<double>(kMaxPositionLsb);
        double low = -range, high = range;
        if (a.has_travel) {
            // Inward, with a nanometre of slack for a travel given in mm that is a whole LSB.
            low = std::ceil(a.travel_min / profile.mm_per_lsb - 1e-9);
            high = std::floor(a.travel_max / profile.mm_per_lsb + 1e-9);
            if (low < -range || high > range || low >= high) {
                throw std::range_error("axis " + a.name +
                                       " travel does not fit the device's position range (+-" +
                                       std::to_string(kMaxPositionLsb) + " LSB)");
            }
        }
        l.min_position.push_back(static_cast<std::int32_t>(low));
        l.max_position.push_back(static_cast<std::int32_t>(high));
    }
    const std::uint64_t pen = delay_ticks(profile.pen_down_delay, profile.tick_hz);
    if (pen > 65535)
        throw std::range_error("pen_down_delay (" + std::to_string(pen) +
                               " ticks) exceeds 65535 ticks");
    l.pen_down_ticks = static_cast<std::uint32_t>(pen);
    return l;
}

const char* device_state_name(device::DeviceState state) {
    static const char* const names[] = {"idle",     "running", "holding",
                                        "stopping", "fault",   "e-stop"};
    const auto n = static_cast<unsigned>(state);
    return n < 6 ? names[n] : "unknown";
}

device::DeviceState device_state_of_wire(unsigned raw) {
    return static_cast<device::DeviceState>(raw < 255 ? raw : 255u);
}

std::string fault_text(std::uint16_t fault_code) {
    char name[64];
    device::fault_name(static_cast<device::FaultCode>(fault_code), name, sizeof name);
    return name;
}

std::string fault_suffix(device::DeviceState state, std::uint16_t fault_code) {
    if (state != device::DeviceState::kFault) return "";
    return " (" + fault_text(fault_code) + ")";
}

std::string position_text(const MachineProfile& profile, const std::int32_t* lsb,
                          std::size_t count) {
    std::string mm, raw;
    char value[48];
    for (std::size_t a = 0; a < count && a < profile.axes.size(); ++a) {
        std::snprintf(value, sizeof value, "%.4f", lsb[a] * profile.mm_per_lsb);
        mm += (a ? " " : "") + profile.axes[a].name + " " + value;
        raw += (a ? " " : "") + std::to_string(lsb[a]);
    }
    return mm + " mm (" + raw + " LSB)";
}

unsigned axis_index(const MachineProfile& profile, const std::string& name) {
    for (std::size_t i = 0; i < profile.axes.size(); ++i) {
        if (profile.axes[i].name == name) return static_cast<unsigned>(i);
    }
    throw std::invalid_argument("the machine profile has no axis \"" + name + "\"");
}

std::vector<HomingSetup> homing_setups(const MachineProfile& profile) {
    std::vector<HomingSetup> out;
    const double q = profile.mm_per_lsb;
    for (const HomingAxisConfig& h : profile.gpio.home) {
        HomingSetup s;
        s.axis_name = h.axis;
        s.switch_name = h.switch_name;
        s.side = h.switch_name.back() == '+' ? device::LimitSide::kPositive
                                             : device::LimitSide::kNegative;
        device::HomingConfig& c = s.config;
        c.axis = axis_index(profile, h.axis);
        c.toward_positive = s.side == device::LimitSide::kPositive;
        const std::string where = "gpio.home." + h.axis + ".";
        c.search_velocity = positive_lsb(h.search_velocity, q, where + "search_velocity");
        c.latch_velocity = positive_lsb(h.latch_velocity, q, where + "latch_velocity");
        c.backoff = positive_lsb(h.backoff, q, where + "backoff");
        c.max_travel = positive_lsb(h.max_travel, q, where + "max_travel");
        c.pull_off = h.pull_off > 0 ? positive_lsb(h.pull_off, q, where + "pull_off") : 0;
        const double home = std::round(h.position / q);
        if (std::fabs(home) > static_cast<double>(kMaxPositionLsb)) {
            throw std::range_error(where + "position is beyond the device's position range");
        }
        c.home_position = static_cast<Lsb>(home);
        out.push_back(s);
    }
    return out;
}

}  // namespace pathstream::host
