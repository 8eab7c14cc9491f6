#include "pathstream/linux_device/machine_homing.hpp"

#include <sstream>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/status.hpp"

namespace pathstream::linux_device {
namespace {

std::string mm(double lsb, double mm_per_lsb) {
    std::ostringstream s;
    s.precision(3);
    s << std::fixed << lsb * mm_per_lsb << " mm";
    return s.str();
}

const char* phase_text(device::HomingPhase p) {
    switch (p) {
        case device::HomingPhase::kSearch:
            return "searching";
        case device::HomingPhase::kSearchStop:
            return "switch seen, stopping";
        case device::HomingPhase::kBackoff:
            return "backing off";
        case device::HomingPhase::kLatch:
            return "approaching slowly";
        case device::HomingPhase::kSetZero:
            return "setting zero";
        case device::HomingPhase::kPullOff:
            return "pulling off the switch";
        default:
            return nullptr;
    }
}

std::string failure(const linux_device::AnyMotionDevice& d, const linux_device::DeviceIo& io,
                    const host::HomingSetup& s, double q) {
    const device::HomingConfig& c = s.config;
    std::string why;
    switch (io.homing_error()) {
        case device::HomingError::kSwitchNotFound:
            why = "switch " + s.switch_name + " not found within " + mm(c.max_travel, q) +
                  " (max_travel)";
            break;
        case device::HomingError::kSwitchStuck:
            why = "switch " + s.switch_name + " still active after moving off it (backoff " +
                  mm(c.backoff, q) + ", pull_off " + mm(c.pull_off, q) +
                  "): check its wiring and active_low";
            break;
        case device::HomingError::kLatchNotFound:
            why = "the slow approach did not find switch " + s.switch_name + " again";
            break;
        case device::HomingError::kInterrupted: {
            char name[64];
            device::fault_name(static_cast<device::FaultCode>(d.fault_code()), name, sizeof name);
            why = d.state() == device::DeviceState::kEstop
                      ? std::string("interrupted by the e-stop")
                      : std::string("interrupted by a fault: ") + name;
            break;
        }
        case device::HomingError::kBadConfig:
            why = "a homing velocity or distance is out of range";
            break;
        case device::HomingError::kDeviceRefused:
            why = std::string("the device refused a homing step: ") +
                  status_name(io.homing_error_status());
            break;
        case device::HomingError::kNone:
            why = "stopped";
            break;
    }
    return "homing " + s.axis_name + ": " + why;
}

}  // namespace

HomingRunLog::HomingRunLog(const linux_device::AnyMotionDevice& device,
                           const linux_device::DeviceIo& io, std::vector<host::HomingSetup> setups,
                           double mm_per_lsb)
    : device_(device), io_(io), setups_(std::move(setups)), mm_per_lsb_(mm_per_lsb) {}

void HomingRunLog::after_tick(const HomingLog& log) {
    const bool busy = io_.homing_run_busy();
    if (busy && !busy_) log("homing run started by a bus command");
    const auto setup_of = [&](unsigned axis) -> const host::HomingSetup* {
        for (const host::HomingSetup& s : setups_) {
            if (s.config.axis == axis) return &s;
        }
        return nullptr;
    };
    const bool sequencer_busy = io_.homing_busy();
    const unsigned axis = io_.homing_axis();
    // An axis's sequence ended (the next axis may have started in the same tick).
    if (sequencer_busy_ && (!sequencer_busy || axis != axis_)) {
        if (const host::HomingSetup* s = setup_of(axis_)) {
            if (io_.homing_report(axis_).state == device::AxisHoming::kHomed) {
                log("  " + s->axis_name +
                    ": homed: switch point = " + mm(s->config.home_position, mm_per_lsb_) +
                    ", now at " + mm(device_.position(axis_), mm_per_lsb_));
            } else {
                log(failure(device_, io_, *s, mm_per_lsb_));
            }
        }
    }
    if (sequencer_busy && (!sequencer_busy_ || axis != axis_ || io_.homing_phase() != phase_)) {
        phase_ = io_.homing_phase();
        const host::HomingSetup* s = setup_of(axis);
        const char* t = phase_text(phase_);
        if (s != nullptr && t != nullptr) log("  " + s->axis_name + ": " + t);
    }
    if (!busy && busy_) log("homing run ended");
    axis_ = axis;
    sequencer_busy_ = sequencer_busy;
    busy_ = busy;
}

void set_homing_plan(linux_device::DeviceIo& io, const std::vector<host::HomingSetup>& setups) {
    std::vector<device::HomingAxis> plan;
    for (const host::HomingSetup& s : setups) plan.push_back({s.config, s.side});
    if (io.set_homing_plan(plan.data(), static_cast<unsigned>(plan.size())) == Status::kOk) return;
    for (const host::HomingSetup& s : setups) {
        device::HomingAxis one{s.config, s.side};
        if (io.set_homing_plan(&one, 1) != Status::kOk) {
            (void)io.set_homing_plan(nullptr, 0);
            throw HomingFailed("homing " + s.axis_name + ": switch " + s.switch_name +
                               " is not wired");
        }
    }
    (void)io.set_homing_plan(nullptr, 0);
    throw HomingFailed("gpio.home: an axis is homed twice, or beyond the device's axes");
}

std::vector<HomedAxis> home_axes(linux_device::AnyMotionDevice& device, linux_device::DeviceIo& io,
                                 const std::vector<host::HomingSetup>& setups, double mm_per_lsb,
                                 const RunTicksUntil& run_until, const HomingLog& log) {
    set_homing_plan(io, setups);
    std::vector<HomedAxis> homed;
    for (const host::HomingSetup& s : setups) {
        const device::HomingConfig& c = s.config;
        log("homing " + s.axis_name + " toward switch " + s.switch_name + ": search at " +
            mm(c.search_velocity, mm_per_lsb) + "/s for at most " + mm(c.max_travel, mm_per_lsb) +
            ", latch at " + mm(c.latch_velocity, mm_per_lsb) + "/s");
        if (Status st = io.start_homing_run(1u << c.axis); st != Status::kOk) {
            throw HomingFailed(failure(device, io, s, mm_per_lsb));
        }
        const std::uint64_t t0 = device.ticks_run();
        device::HomingPhase shown = device::HomingPhase::kStarting;
        const bool finished = run_until([&] {
            const device::HomingPhase p = io.homing_phase();
            if (p != shown) {
                shown = p;
                if (const char* t = phase_text(p)) log("  " + s.axis_name + ": " + t);
            }
            return !io.homing_run_busy();
        });
        if (!finished) throw HomingFailed("homing " + s.axis_name + ": interrupted");
        if (io.homing_phase() != device::HomingPhase::kDone)
            throw HomingFailed(failure(device, io, s, mm_per_lsb));
        HomedAxis h;
        h.axis_name = s.axis_name;
        h.latch = io.latch_position();
        h.overshoot = io.search_overshoot();
        h.rest = device.position(c.axis);
        h.ticks = device.ticks_run() - t0;
        log("  " + s.axis_name + ": homed: switch point = " + mm(c.home_position, mm_per_lsb) +
            ", now at " + mm(h.rest, mm_per_lsb) + " (search overshoot " +
            mm(static_cast<double>(h.overshoot), mm_per_lsb) + ", " + std::to_string(h.ticks) +
            " ticks)");
        homed.push_back(h);
    }
    return homed;
}

}  // namespace pathstream::linux_device
