#include "device_command.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/host/atomic_file.hpp"
#include "pathstream/host/device_setup.hpp"
#include "pathstream/host/machine.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/linux_device/machine_homing.hpp"
#include "pathstream/linux_device/machine_lines.hpp"
#include "pathstream/sim/can_device.hpp"
#include "pathstream/sim/modbus_device.hpp"

namespace pathstream::host {
namespace {

std::atomic<bool> g_stop{false};

// One --position value: mm ("139.322"), or LSB with the suffix "lsb" ("139322lsb"); a whole
// number of LSB within the core's position range, else std::invalid_argument (exit 2).
Lsb parse_position(const std::string& text, double mm_per_lsb) {
    const bool lsb = text.size() > 3 && text.compare(text.size() - 3, 3, "lsb") == 0;
    const std::string number = lsb ? text.substr(0, text.size() - 3) : text;
    double value = 0;
    std::size_t used = 0;
    try {
        value = std::stod(number, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != number.size() || !std::isfinite(value)) {
        throw std::invalid_argument("--position: '" + text + "' is not a number of mm (or of LSB with the suffix lsb)");
    }
    const double in_lsb = lsb ? value : value / mm_per_lsb;
    const double whole = std::round(in_lsb);
    if (std::fabs(in_lsb - whole) > 1e-6 * std::max(1.0, std::fabs(whole))) {
        throw std::invalid_argument("--position: '" + text + "' is not a whole number of LSB (" +
                                    std::to_string(mm_per_lsb) + " mm each)");
    }
    if (std::fabs(whole) > static_cast<double>(kMaxPositionLsb)) {
        throw std::invalid_argument("--position: '" + text + "' is outside the core's position range (+-" +
                                    std::to_string(kMaxPositionLsb) + " LSB)");
    }
    return static_cast<Lsb>(whole);
}
extern "C" void on_signal(int) { g_stop.store(true); }

void write_record(const sim::SimulatedMotionDevice& d, const std::string& path) {
    AtomicFile f(path);
    std::ostream& out = f.stream();
    static const char* const names[] = {"x", "y", "z", "a", "b", "c", "u", "v"};
    out << "tick";
    for (unsigned a = 0; a < d.axes(); ++a) out << ',' << names[a];
    out << ",pen\n";
    const auto& s = d.recorded_setpoints();
    const auto& t = d.recorded_ticks();
    for (std::size_t k = 0; k < t.size(); ++k) {
        out << k;
        for (unsigned a = 0; a < d.axes(); ++a) out << ',' << s[k * d.axes() + a];
        out << ',' << ((t[k].outputs & 1u) != 0 ? 1 : 0) << '\n';
    }
    f.commit();
}

// Logs the transitions an operator must see (e-stop, faults with their names, the way back
// to idle); a streaming host sees the same in the status block.
class StateLog {
public:
    void after_tick(const sim::SimulatedMotionDevice& d) {
        const std::uint8_t s = d.state();
        if (s == last_) return;
        const auto st = static_cast<device::DeviceState>(s);
        const auto was = static_cast<device::DeviceState>(last_);
        last_ = s;
        if (st == device::DeviceState::kEstop) {
            std::cout << "pathstream device: E-STOP at tick " << d.ticks_run() << ": axes held, drives disabled; "
                      << "release the e-stop and send reset" << std::endl;
        } else if (st == device::DeviceState::kFault) {
            char name[64];
            device::fault_name(static_cast<device::FaultCode>(d.fault_code()), name, sizeof name);
            std::cout << "pathstream device: FAULT at tick " << d.ticks_run() << ": " << name
                      << "; drives disabled until reset" << std::endl;
        } else if (st == device::DeviceState::kIdle &&
                   (was == device::DeviceState::kEstop || was == device::DeviceState::kFault)) {
            std::cout << "pathstream device: reset: idle at tick " << d.ticks_run() << std::endl;
        }
    }

private:
    std::uint8_t last_ = static_cast<std::uint8_t>(device::DeviceState::kIdle);
};

// Homes in real time (times --time-scale), before any bus is served: a host cannot start a
// job on a half-homed machine. SIGINT/SIGTERM end homing at the next tick (exit 6); the lines
// are then released with enable and pen inactive (MachineLines).
void home(sim::SimulatedMotionDevice& device, sim::DeviceIo& io, const MachineProfile& profile, double time_scale) {
    sim::DeviceLoopOptions loop;
    loop.time_scale = time_scale;
    StateLog state_log;
    const auto run_until = [&](const std::function<bool()>& done) {
        std::atomic<bool> finished{false};
        sim::run_paced_loop(
            [&] {
                device.tick();
                state_log.after_tick(device);
                if (done() || g_stop.load()) finished.store(true);
            },
            [&] { return device.tick_hz(); }, [](std::chrono::microseconds w) { std::this_thread::sleep_for(w); },
            loop, finished);
        return done();
    };
    const auto log = [](const std::string& line) { std::cout << "pathstream device: " << line << std::endl; };
    try {
        (void)linux_device::home_axes(device, io, homing_setups(profile), profile.mm_per_lsb, run_until, log);
    } catch (const linux_device::HomingFailed& e) {
        throw StreamError(e.what());
    }
}

// Configuration, GPIO and homing from the profile, shared by every transport.
struct Machine {
    std::optional<MachineProfile> profile;
    std::optional<linux_device::MachineLines> lines;
    sim::DeviceIo* io = nullptr;
};

Machine prepare_machine(sim::SimulatedMotionDevice& device, const DeviceCommandOptions& o,
                        const std::optional<MachineProfile>& profile) {
    Machine m;
    if (!profile) return m;
    m.profile = profile;
    const DeviceLimitsLsb limits = device_limits(*profile);
    if (Status s = device.configure(limits); s != Status::kOk) {
        throw std::invalid_argument(profile->source + ": the device refused the profile's limits: " + status_name(s));
    }
    std::cout << "pathstream device: configured from " << profile->source << ": " << limits.tick_hz << " Hz ticks";
    for (std::size_t a = 0; a < profile->axes.size(); ++a) {
        std::cout << ", " << profile->axes[a].name << " " << limits.max_velocity[a] << " LSB/s "
                  << limits.max_acceleration[a] << " LSB/s^2";
    }
    std::cout << std::endl;
    if (profile->gpio.present && !o.no_gpio) {
        m.lines.emplace(linux_device::MachineLines::open(*profile));
        m.io = &device.attach_io(m.lines->wiring());
        std::cout << "pathstream device: GPIO " << m.lines->summary() << std::endl;
    }
    if (o.home) {
        if (m.io == nullptr) {
            throw std::invalid_argument(profile->source + ": no \"gpio\" object: --home has no switches to home against");
        }
        if (profile->gpio.home.empty()) throw std::invalid_argument(profile->source + ": --home: gpio.home is empty");
        home(device, *m.io, *profile, o.time_scale);
    }
    return m;
}

sim::DeviceLoopOptions loop_options(const DeviceCommandOptions& o) {
    sim::DeviceLoopOptions loop;
    loop.time_scale = o.time_scale;
    loop.run_for = std::chrono::milliseconds(static_cast<long>(o.exit_after * 1000));
    return loop;
}

int run_can_device(const DeviceCommandOptions& o, const std::vector<Lsb>& start,
                   const std::optional<MachineProfile>& profile) {
    auto device = sim::SimulatedCanDevice::create(start, static_cast<std::uint8_t>(o.node));
    device->record(!o.record.empty());
    const Machine machine = prepare_machine(*device, o, profile);
    hal::SocketCanBus bus(o.can_interface);
    std::cout << "pathstream device: " << device->axes() << " axes, native CAN node " << o.node << " on "
              << o.can_interface << " (can://" << o.can_interface << "?node=" << o.node << "&protocol=native)"
              << std::endl;
    StateLog log;
    sim::run_paced_loop(
        [&] {
            device->tick();
            log.after_tick(*device);
        },
        [&] { return device->tick_hz(); }, [&](std::chrono::microseconds w) { device->serve(bus, w); },
        loop_options(o), g_stop);
    const hal::SocketCanCounters& c = bus.counters();
    std::cout << "pathstream device: stopped after " << device->ticks_run() << " ticks, " << c.frames_received << " frames in, "
              << c.frames_sent << " out, " << device->incomplete_transfers() << " incomplete and "
              << device->refused_batches() << " refused batches, " << c.error_frames << " error frames" << std::endl;
    if (!o.record.empty()) write_record(*device, o.record);
    return 0;
}

int run_modbus_device(const DeviceCommandOptions& o, const std::vector<Lsb>& start,
                      const std::optional<MachineProfile>& profile) {
    auto device = sim::SimulatedModbusDevice::create(start);
    device->record(!o.record.empty());
    const Machine machine = prepare_machine(*device, o, profile);
    hal::ModbusServerOptions server_options;
    server_options.unit = o.unit;
    std::string url;
    auto server = [&]() -> hal::ModbusServer {
        if (o.rtu_pty || !o.rtu_device.empty()) {
            hal::ModbusServer s = o.rtu_pty ? hal::ModbusServer::rtu_pty(device->handler(), server_options)
                                            : hal::ModbusServer::rtu(device->handler(),
                                                                     {o.rtu_device, o.baud, o.parity[0], 8, 1},
                                                                     server_options);
            url = "modbus-rtu://" + s.client_device() + "?baud=" + std::to_string(o.baud) + "&parity=" + o.parity +
                  "&unit=" + std::to_string(o.unit);
            return s;
        }
        const auto colon = o.tcp.rfind(':');
        if (colon == std::string::npos) throw std::invalid_argument("--tcp wants HOST:PORT, not '" + o.tcp + "'");
        hal::ModbusTcpEndpoint endpoint;
        endpoint.host = o.tcp.substr(0, colon);
        const int port = std::stoi(o.tcp.substr(colon + 1));
        if (port < 0 || port > 65535) throw std::invalid_argument("--tcp port out of range: " + o.tcp);
        endpoint.port = static_cast<std::uint16_t>(port);
        hal::ModbusServer s = hal::ModbusServer::tcp(device->handler(), endpoint, server_options);
        url = "modbus-tcp://" + endpoint.host + ":" + std::to_string(s.port()) + "?unit=" + std::to_string(o.unit);
        return s;
    }();
    std::cout << "pathstream device: " << device->axes() << " axes, serving " << url << std::endl;
    StateLog log;
    sim::run_paced_loop(
        [&] {
            device->tick();
            log.after_tick(*device);
        },
        [&] { return device->tick_hz(); },
        [&](std::chrono::microseconds w) {
            server.poll_once(std::chrono::duration_cast<std::chrono::milliseconds>(w));
        },
        loop_options(o), g_stop);
    std::cout << "pathstream device: stopped after " << device->ticks_run() << " ticks, " << server.counters().requests.load()
              << " requests (" << server.counters().exceptions.load() << " refused)" << std::endl;
    if (!o.record.empty()) write_record(*device, o.record);
    return 0;
}

}  // namespace

void add_device_command(CLI::App& app, DeviceCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "device",
        "Run the simulated device (the firmware core) as a Modbus TCP/RTU server or a native CAN node "
        "(docs/modbus.md, docs/can.md); with --machine wired to the profile's GPIO lines (docs/gpio.md)");
    cmd->add_option("--axes", o.axes, "axis count (default 2, or the profile's)")->check(CLI::Range(1, 8));
    cmd->add_option("--position", o.position,
                    "initial position per axis in mm (e.g. 139.322,100), or in LSB with the suffix lsb "
                    "(139322lsb); mm per LSB from --machine, else 0.001 (default 0)")
        ->delimiter(',');
    cmd->add_option("--tcp", o.tcp, "serve Modbus TCP on HOST:PORT (port 0: any free port)")->capture_default_str();
    cmd->add_flag("--rtu-pty", o.rtu_pty, "serve Modbus RTU on a new pseudo-terminal (prints its path)");
    cmd->add_option("--rtu", o.rtu_device, "serve Modbus RTU on this serial device");
    cmd->add_option("--baud", o.baud, "RTU baud rate")->capture_default_str();
    cmd->add_option("--parity", o.parity, "RTU parity")->capture_default_str()->check(CLI::IsMember({"N", "E", "O"}));
    cmd->add_option("--unit", o.unit, "RTU unit id")->capture_default_str()->check(CLI::Range(1, 247));
    cmd->add_option("--can", o.can_interface, "serve the native CAN protocol on this SocketCAN interface (docs/can.md)");
    cmd->add_option("--node", o.node, "CAN node id (with --can)")->capture_default_str()->check(CLI::Range(1, 127));
    cmd->add_option("--machine,-m", o.machine,
                    "machine profile: configure the device from it (axes, tick rate, limits) and open its \"gpio\" "
                    "lines: e-stop, limit switches, enable, pen (docs/gpio.md)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--no-gpio", o.no_gpio, "with --machine: do not open the profile's GPIO lines");
    cmd->add_flag("--home", o.home, "home the axes of the profile's gpio.home (in profile order) before serving");
    cmd->add_option("--time-scale", o.time_scale, "run ticks this many times faster than real time")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 1000.0));
    cmd->add_option("--record", o.record, "write every executed path tick to this CSV (tick,x,y,...,pen) at exit");
    cmd->add_option("--exit-after", o.exit_after, "stop after this many seconds (default: at SIGINT/SIGTERM)")
        ->check(CLI::Range(0.0, 1e6));
    cmd->callback([cmd, &o] {
        if (o.home && o.machine.empty()) throw CLI::ValidationError("--home", "needs --machine (the profile's gpio.home)");
        if (o.no_gpio && o.machine.empty()) throw CLI::ValidationError("--no-gpio", "needs --machine");
        if (o.no_gpio && o.home) throw CLI::ValidationError("--home", "homes against the GPIO switches: not with --no-gpio");
        if (!o.can_interface.empty() && (o.rtu_pty || !o.rtu_device.empty() || cmd->count("--tcp") > 0)) {
            throw CLI::ValidationError("--can", "serves CAN; --tcp, --rtu and --rtu-pty serve Modbus: choose one");
        }
        if (!o.machine.empty() && cmd->count("--axes") > 0) {
            throw CLI::ValidationError("--axes", "the axis count comes from --machine");
        }
    });
}

int run_device(const DeviceCommandOptions& o) {
    std::optional<MachineProfile> profile;
    if (!o.machine.empty()) profile = load_machine_profile(o.machine);
    const unsigned axes = profile ? static_cast<unsigned>(profile->axes.size()) : o.axes;
    std::vector<Lsb> start(axes, 0);
    if (!o.position.empty()) {
        if (o.position.size() != axes) {
            std::cerr << "pathstream device: --position has " << o.position.size() << " values for " << axes
                      << " axes\n";
            return 2;
        }
        const double mm_per_lsb = profile ? profile->mm_per_lsb : 0.001;
        for (unsigned a = 0; a < axes; ++a) start[a] = parse_position(o.position[a], mm_per_lsb);
    }
    // Before homing: an interrupted homing must stop cleanly too.
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    if (!o.can_interface.empty()) return run_can_device(o, start, profile);
    return run_modbus_device(o, start, profile);
}

}  // namespace pathstream::host
