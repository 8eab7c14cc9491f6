#include "device_command.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <system_error>

#include "failure_exit.hpp"
#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/hal/gpio_gpiod.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/linux_device/device_runtime.hpp"
#include "pathstream/linux_device/machine_homing.hpp"
#include "pathstream/linux_device/machine_lines.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/exit_codes.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/machine/position_argument.hpp"
#include "pathstream/sim/gpio_sim_pull.hpp"
#include "pathstream/sim/machine_switches.hpp"

namespace pathstream::device_cli {
namespace {

using namespace pathstream::host;

std::atomic<bool> g_stop{false};

extern "C" void on_signal(int) {
    g_stop.store(true);
}

// --sim-switch: the profile's limit switches closed by the simulated axes, on the gpio-sim
// lines the device reads (the kernel delivers their edges as a real pin's). Read and checked
// before any line is opened: a wrong option is reported as one.
struct SimSwitch {
    std::string name;
    sim::SwitchPlacement placement;
    GpioLineConfig line;
};

std::vector<SimSwitch> read_sim_switches(const DeviceCommandOptions& o,
                                         const MachineProfile& profile) {
    const GpioConfig& g = profile.gpio;
    std::string names;
    for (const auto& [name, line] : g.limits) names += (names.empty() ? "" : ", ") + name;
    std::vector<SimSwitch> out;
    for (const std::string& spec : o.sim_switches) {
        const auto eq = spec.find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
            throw std::invalid_argument("--sim-switch " + spec +
                                        ": want NAME=POSITION, e.g. x-=-5");
        }
        SimSwitch sw;
        sw.name = spec.substr(0, eq);
        const auto it = std::find_if(g.limits.begin(), g.limits.end(),
                                     [&sw](const auto& l) { return l.first == sw.name; });
        if (it == g.limits.end()) {
            throw std::invalid_argument(
                "--sim-switch " + spec + ": " + profile.source + " has no limit switch " + sw.name +
                (names.empty() ? " (gpio.limits is empty)" : " (its switches: " + names + ")"));
        }
        for (const SimSwitch& other : out) {
            if (other.name == sw.name)
                throw std::invalid_argument("--sim-switch " + sw.name + ": given twice");
        }
        sw.line = it->second;
        sim::SwitchPlacement& p = sw.placement;
        p.axis = axis_index(profile, sw.name.substr(0, sw.name.size() - 1));
        p.side =
            sw.name.back() == '+' ? device::LimitSide::kPositive : device::LimitSide::kNegative;
        p.trigger = parse_position_argument(spec.substr(eq + 1), profile.mm_per_lsb,
                                            "--sim-switch " + sw.name);
        p.hysteresis = static_cast<Lsb>(std::llround(o.switch_hysteresis / profile.mm_per_lsb));
        p.bounces = o.switch_bounces;
        p.bounce_ticks =
            std::max(o.switch_bounce_ticks != 0 ? o.switch_bounce_ticks : 4 * o.switch_bounces,
                     2 * o.switch_bounces);
        p.seed = o.switch_seed + out.size();
        out.push_back(sw);
    }
    return out;
}

void place_sim_switches(sim::MachineSwitches& machine_switches,
                        const std::vector<SimSwitch>& switches, const MachineProfile& profile,
                        const linux_device::DeviceLog& log) {
    for (const SimSwitch& sw : switches) {
        const sim::SwitchPlacement& p = sw.placement;
        const hal::GpioLineLocation where =
            hal::locate_gpiod_line(linux_device::line_spec(profile.gpio.chip, sw.line));
        auto pull =
            std::make_shared<sim::GpioSimPull>(where.chip_name, where.offset, sw.line.active_low);
        machine_switches.place(p, [pull](bool closed) { pull->set(closed); });
        char text[160];
        std::snprintf(
            text, sizeof text,
            "simulated switch %s at %.4f mm (hysteresis %.4f mm, %u bounces within %u ticks): ",
            sw.name.c_str(), static_cast<double>(p.trigger) * profile.mm_per_lsb,
            static_cast<double>(p.hysteresis) * profile.mm_per_lsb, p.bounces, p.bounce_ticks);
        log("gpio", text + pull->path());
    }
}

}  // namespace

void add_device_command(CLI::App& app, DeviceCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "device",
        "Run the device (the firmware core) as a Modbus TCP/RTU server or a native CAN node "
        "(docs/modbus.md, docs/can.md); with --machine wired to the profile's GPIO lines "
        "(docs/gpio.md)");
    cmd->add_option("--axes", o.axes, "axis count (default 2, or the profile's)")
        ->check(CLI::Range(1, 8));
    cmd->add_option(
           "--position", o.position,
           "initial position per axis in mm (e.g. 139.322,100), or in LSB with the suffix lsb "
           "(139322lsb); mm per LSB from --machine, else 0.001 (default 0)")
        ->delimiter(',');
    cmd->add_option("--tcp", o.run.tcp, "serve Modbus TCP on HOST:PORT (port 0: any free port)")
        ->capture_default_str();
    cmd->add_flag("--rtu-pty", o.run.rtu_pty,
                  "serve Modbus RTU on a new pseudo-terminal (prints its path)");
    cmd->add_option("--rtu", o.run.rtu_device, "serve Modbus RTU on this serial device");
    cmd->add_option("--baud", o.run.baud, "RTU baud rate")->capture_default_str();
    cmd->add_option("--parity", o.run.parity, "RTU parity")
        ->capture_default_str()
        ->check(CLI::IsMember({"N", "E", "O"}));
    cmd->add_option("--unit", o.run.unit, "RTU unit id")
        ->capture_default_str()
        ->check(CLI::Range(1, 247));
    cmd->add_option("--can", o.run.can_interface,
                    "serve the native CAN protocol on this SocketCAN interface (docs/can.md)");
    cmd->add_option("--node", o.run.node, "CAN node id (with --can)")
        ->capture_default_str()
        ->check(CLI::Range(1, 127));
    cmd->add_option("--machine,-m", o.machine,
                    "machine profile: configure the device from it (axes, tick rate, limits), "
                    "open its \"gpio\" lines (e-stop, limit switches, enable, pen, spindle, "
                    "coolant) and its \"output_coils\" module (docs/gpio.md)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--no-gpio", o.run.no_gpio,
                  "with --machine: do not open the profile's GPIO lines");
    cmd->add_flag("--home", o.run.home,
                  "home the axes of the profile's gpio.home (in profile order) before serving");
    cmd->add_option("--time-scale", o.run.time_scale,
                    "run ticks this many times faster than real time")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 1000.0));
    cmd->add_option("--record", o.run.record,
                    "write every executed path tick to this CSV (tick,x,y,...,pen) at exit");
    cmd->add_option("--exit-after", o.run.exit_after,
                    "stop after this many seconds (default: at SIGINT/SIGTERM)")
        ->check(CLI::Range(0.0, 1e6));
    cmd->add_flag(
        "--log-json", o.run.log_json,
        "print the log as NDJSON (one JSON object per line, docs/events.md) instead of text");
    cmd->add_option(
        "--sim-switch", o.sim_switches,
        "play the profile's limit switch NAME (e.g. x-) from the simulated axis on a gpio-sim "
        "chip: "
        "closed at POSITION (mm, or LSB with the suffix lsb) and beyond; NAME=POSITION, repeatable "
        "(docs/gpio.md)");
    cmd->add_option(
           "--switch-hysteresis", o.switch_hysteresis,
           "with --sim-switch: mm the axis moves back past the trigger before the switch opens")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 100.0));
    cmd->add_option(
           "--switch-bounce", o.switch_bounces,
           "with --sim-switch: times the contact opens and closes again after every change")
        ->capture_default_str()
        ->check(CLI::Range(0, 100));
    cmd->add_option("--switch-bounce-ticks", o.switch_bounce_ticks,
                    "with --sim-switch: ticks the bounces fall within (0: 4 x --switch-bounce; at "
                    "least 2 x it)")
        ->capture_default_str()
        ->check(CLI::Range(0, 100000));
    cmd->add_option("--switch-seed", o.switch_seed, "with --sim-switch: seed of the bounces' ticks")
        ->capture_default_str();
    cmd->callback([cmd, &o] {
        if (!o.sim_switches.empty() && o.machine.empty()) {
            throw CLI::ValidationError("--sim-switch",
                                       "needs --machine (the profile's gpio.limits)");
        }
        if (!o.sim_switches.empty() && o.run.no_gpio) {
            throw CLI::ValidationError("--sim-switch",
                                       "drives the profile's GPIO lines: not with --no-gpio");
        }
        for (const char* opt :
             {"--switch-hysteresis", "--switch-bounce", "--switch-bounce-ticks", "--switch-seed"}) {
            if (cmd->count(opt) > 0 && o.sim_switches.empty())
                throw CLI::ValidationError(opt, "needs --sim-switch");
        }
        if (o.run.home && o.machine.empty())
            throw CLI::ValidationError("--home", "needs --machine (the profile's gpio.home)");
        if (o.run.no_gpio && o.machine.empty())
            throw CLI::ValidationError("--no-gpio", "needs --machine");
        if (o.run.no_gpio && o.run.home)
            throw CLI::ValidationError("--home",
                                       "homes against the GPIO switches: not with --no-gpio");
        if (!o.run.can_interface.empty() &&
            (o.run.rtu_pty || !o.run.rtu_device.empty() || cmd->count("--tcp") > 0)) {
            throw CLI::ValidationError(
                "--can", "serves CAN; --tcp, --rtu and --rtu-pty serve Modbus: choose one");
        }
        if (!o.machine.empty() && cmd->count("--axes") > 0) {
            throw CLI::ValidationError("--axes", "the axis count comes from --machine");
        }
    });
}

int run_device(const DeviceCommandOptions& o) {
    try {
        std::optional<MachineProfile> profile;
        if (!o.machine.empty()) profile = load_machine_profile(o.machine);
        const unsigned axes = profile ? static_cast<unsigned>(profile->axes.size()) : o.axes;
        std::vector<Lsb> start(axes, 0);
        if (!o.position.empty()) {
            if (o.position.size() != axes) {
                std::cerr << "pathstream device: --position has " << o.position.size()
                          << " values for " << axes << " axes\n";
                return kExitUsage;
            }
            const double mm_per_lsb = profile ? profile->mm_per_lsb : 0.001;
            for (unsigned a = 0; a < axes; ++a)
                start[a] = parse_position_argument(o.position[a], mm_per_lsb, "--position");
        }
        // Read and checked before any line is opened: a wrong option is reported as one.
        const std::vector<SimSwitch> switches =
            profile ? read_sim_switches(o, *profile) : std::vector<SimSwitch>{};
        sim::MachineSwitches machine_switches;
        const linux_device::AttachMachine attach = [&](linux_device::AnyMotionDevice& device,
                                                       const linux_device::DeviceLog& log) {
            if (switches.empty()) return;
            place_sim_switches(machine_switches, switches, *profile, log);
            device.observe_ticks(&machine_switches);
        };
        // Before homing: an interrupted homing must stop cleanly too.
        std::signal(SIGINT, on_signal);
        std::signal(SIGTERM, on_signal);
        return linux_device::run_device_runtime(o.run, start, profile, attach, g_stop);
    } catch (const linux_device::HomingFailed& e) {
        std::cerr << "pathstream: device: " << e.what() << '\n';
        return kExitDevice;
    } catch (...) {
        return failure_exit(std::current_exception());
    }
}

}  // namespace pathstream::device_cli
