#include "device_command.hpp"

#include "exit_codes.hpp"
#include "pathstream/machine/position_argument.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <thread>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/hal/gpio_gpiod.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/machine/atomic_file.hpp"
#include "pathstream/machine/core_span_conversion.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/host/events.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/linux_device/machine_homing.hpp"
#include "pathstream/linux_device/machine_lines.hpp"
#include "pathstream/sim/can_device.hpp"
#include "pathstream/sim/gpio_sim_pull.hpp"
#include "pathstream/sim/modbus_device.hpp"

namespace pathstream::host {
namespace {

std::atomic<bool> g_stop{false};

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

// The device's log: one line per event on standard output, stamped with the time (ISO-8601
// UTC, ms); text for people or, with --log-json, NDJSON whose `message` is the text.
class DeviceLog {
public:
    explicit DeviceLog(bool json) : json_(json) {}

    void operator()(const char* event, const std::string& text,
                    const EventJson& fields = EventJson::object()) const {
        const std::string time = iso8601_utc(std::chrono::system_clock::now());
        if (!json_) {
            std::cout << time << " pathstream device: " << text << std::endl;
            return;
        }
        EventJson line;
        line["time"] = time;
        line["event"] = event;
        for (auto it = fields.begin(); it != fields.end(); ++it) line[it.key()] = it.value();
        line["message"] = text;
        std::cout << line.dump(-1, ' ', false, EventJson::error_handler_t::replace) << std::endl;
    }

private:
    bool json_;
};

// What the log follows of the device's status after every tick.
struct DeviceView {
    unsigned state = 0;
    std::uint16_t fault_code = 0;
    std::uint32_t job = 0;  ///< job of the span in progress or last played (0: none)
    std::uint32_t finished_job = 0, finished_job_ticks = 0;
};

// A reader of `d`'s status as the log follows it.
std::function<DeviceView()> status_reader(const sim::SimulatedMotionDevice& d) {
    return [&d] { return DeviceView{d.state(), d.fault_code(), d.job(), d.finished_job(), d.finished_job_ticks()}; };
}

// Logs what an operator follows: client connections, jobs starting and finishing, every state
// change and faults by name (the e-stop, fault and reset lines keep their words: tests and
// scripts look for them); a streaming host sees the same in the status block.
class DeviceWatch {
public:
    DeviceWatch(const DeviceLog& log, std::function<DeviceView()> read)
        : log_(log), read_(std::move(read)), last_(read_()), started_job_(last_.job) {}

    // After every tick: the job that ended, then the state, then the job that began.
    void after_tick(const sim::SimulatedMotionDevice& d) {
        const DeviceView v = read_();
        const std::uint64_t tick = d.ticks_run();
        if (v.finished_job != last_.finished_job && v.finished_job != 0) job_end(v, tick);
        const bool new_fault = v.state == kFault && v.fault_code != last_.fault_code;
        if (v.state != last_.state || new_fault) state_change(v, tick);
        if (v.state == kRunning && v.job != 0 && v.job != started_job_) job_start(v, tick);
        last_ = v;
    }

    // After every Modbus poll: connections accepted and closed since the last one. At most
    // kConnectionLines lines in kConnectionWindow; beyond them a client that connects and
    // leaves in a loop is counted, and one line per window says how many.
    // `last`: the device stops, the counted connections are said now.
    void after_poll(const hal::ModbusServer& server, bool last = false) {
        const hal::ModbusServerCounters& c = server.counters();
        const std::uint64_t closed = c.connections_closed.load(),
                            accepted = c.connections_accepted.load();
        const auto now = std::chrono::steady_clock::now();
        if (now - window_start_ >= kConnectionWindow || last) {
            if (quiet_accepted_ + quiet_closed_ > 0) {
                log_("connections",
                     std::to_string(quiet_accepted_) + " more clients connected and " + std::to_string(quiet_closed_) +
                         " disconnected in " + std::to_string(kConnectionWindow.count()) + " s (" +
                         std::to_string(open_after(accepted, closed)) + " open)",
                     {{"connected", quiet_accepted_}, {"disconnected", quiet_closed_},
                      {"open", open_after(accepted, closed)}});
            }
            window_start_ = now;
            window_lines_ = quiet_accepted_ = quiet_closed_ = 0;
        }
        while (accepted_ < accepted) {
            ++accepted_;
            if (window_lines_ < kConnectionLines) {
                ++window_lines_;
                log_("connect", "client connected (" + std::to_string(open()) + " open)", {{"open", open()}});
            } else {
                ++quiet_accepted_;
            }
        }
        while (closed_ < closed && closed_ < accepted_) {
            ++closed_;
            if (window_lines_ < kConnectionLines) {
                ++window_lines_;
                log_("disconnect", "client disconnected (" + std::to_string(open()) + " open)", {{"open", open()}});
            } else {
                ++quiet_closed_;
            }
        }
    }

private:
    static constexpr unsigned kRunning = static_cast<unsigned>(device::DeviceState::kRunning);
    static constexpr unsigned kFault = static_cast<unsigned>(device::DeviceState::kFault);
    static constexpr unsigned kEstop = static_cast<unsigned>(device::DeviceState::kEstop);
    static constexpr unsigned kIdle = static_cast<unsigned>(device::DeviceState::kIdle);

    static constexpr unsigned kConnectionLines = 20;
    static constexpr std::chrono::seconds kConnectionWindow{10};

    std::uint64_t open() const { return accepted_ - closed_; }
    static std::uint64_t open_after(std::uint64_t accepted, std::uint64_t closed) {
        return accepted > closed ? accepted - closed : 0;
    }

    void job_start(const DeviceView& v, std::uint64_t tick) {
        started_job_ = v.job;
        log_("job_start",
             "job " + std::to_string(v.job) + " started at tick " + std::to_string(tick),
             {{"job", v.job}, {"tick", tick}});
    }

    void job_end(const DeviceView& v, std::uint64_t tick) {
        log_("job_end",
             "job " + std::to_string(v.finished_job) + " finished at tick " + std::to_string(tick) +
                 ": " + std::to_string(v.finished_job_ticks) + " path ticks",
             {{"job", v.finished_job}, {"ticks", v.finished_job_ticks}, {"tick", tick}});
    }

    void state_change(const DeviceView& v, std::uint64_t tick) {
        EventJson fields = {{"state", device_state_name(v.state)},
                            {"code", v.state},
                            {"was", device_state_name(last_.state)},
                            {"tick", tick}};
        const std::string at = " at tick " + std::to_string(tick);
        std::string text;
        if (v.state == kEstop) {
            text =
                "E-STOP" + at + ": axes held, drives disabled; release the e-stop and send reset";
        } else if (v.state == kFault) {
            fields["fault"] = fault_text(v.fault_code);
            fields["fault_code"] = v.fault_code;
            text = "FAULT" + at + ": " + fault_text(v.fault_code) + "; drives disabled until reset";
        } else if (v.state == kIdle && (last_.state == kEstop || last_.state == kFault)) {
            text = "reset: idle" + at;
        } else {
            text = std::string("state ") + device_state_name(v.state) + " (was " +
                   device_state_name(last_.state) + ")" + at;
        }
        log_("state", text, fields);
    }

    const DeviceLog& log_;
    std::function<DeviceView()> read_;
    DeviceView last_;
    std::uint32_t started_job_ = 0;
    std::uint64_t accepted_ = 0, closed_ = 0;
    std::chrono::steady_clock::time_point window_start_ = std::chrono::steady_clock::now();
    unsigned window_lines_ = 0;
    std::uint64_t quiet_accepted_ = 0, quiet_closed_ = 0;
};

// Homes in real time (times --time-scale), before any bus is served: a host cannot start a
// job on a half-homed machine. SIGINT/SIGTERM end homing at the next tick (exit 6); the lines
// are then released with enable and pen inactive (MachineLines).
void home(sim::SimulatedMotionDevice& device, sim::DeviceIo& io, const MachineProfile& profile,
          double time_scale, const DeviceLog& log, DeviceWatch& watch) {
    sim::DeviceLoopOptions loop;
    loop.time_scale = time_scale;
    const auto run_until = [&](const std::function<bool()>& done) {
        std::atomic<bool> finished{false};
        sim::run_paced_loop(
            [&] {
                device.tick();
                watch.after_tick(device);
                if (done() || g_stop.load()) finished.store(true);
            },
            [&] { return device.tick_hz(); }, [](std::chrono::microseconds w) { std::this_thread::sleep_for(w); },
            loop, finished);
        return done();
    };
    const auto phase = [&log](const std::string& line) { log("homing", line); };
    try {
        (void)linux_device::home_axes(device, io, homing_setups(profile), profile.mm_per_lsb,
                                      run_until, phase);
    } catch (const linux_device::HomingFailed& e) {
        throw StreamError(e.what());
    }
}

// --sim-switch: the profile's limit switches closed by the simulated axes, on the gpio-sim
// lines the device reads (the kernel delivers their edges as a real pin's). Read and checked
// before any line is opened: a wrong option is reported as one.
struct SimSwitch {
    std::string name;
    sim::SwitchPlacement placement;
    GpioLineConfig line;
};

std::vector<SimSwitch> read_sim_switches(const DeviceCommandOptions& o, const MachineProfile& profile) {
    const GpioConfig& g = profile.gpio;
    std::string names;
    for (const auto& [name, line] : g.limits) names += (names.empty() ? "" : ", ") + name;
    std::vector<SimSwitch> out;
    for (const std::string& spec : o.sim_switches) {
        const auto eq = spec.find('=');
        if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size()) {
            throw std::invalid_argument("--sim-switch " + spec + ": want NAME=POSITION, e.g. x-=-5");
        }
        SimSwitch sw;
        sw.name = spec.substr(0, eq);
        const auto it = std::find_if(g.limits.begin(), g.limits.end(), [&sw](const auto& l) { return l.first == sw.name; });
        if (it == g.limits.end()) {
            throw std::invalid_argument("--sim-switch " + spec + ": " + profile.source + " has no limit switch " + sw.name +
                                        (names.empty() ? " (gpio.limits is empty)" : " (its switches: " + names + ")"));
        }
        for (const SimSwitch& other : out) {
            if (other.name == sw.name) throw std::invalid_argument("--sim-switch " + sw.name + ": given twice");
        }
        sw.line = it->second;
        sim::SwitchPlacement& p = sw.placement;
        p.axis = axis_index(profile, sw.name.substr(0, sw.name.size() - 1));
        p.side = sw.name.back() == '+' ? device::LimitSide::kPositive : device::LimitSide::kNegative;
        p.trigger = parse_position_argument(spec.substr(eq + 1), profile.mm_per_lsb, "--sim-switch " + sw.name);
        p.hysteresis = static_cast<Lsb>(std::llround(o.switch_hysteresis / profile.mm_per_lsb));
        p.bounces = o.switch_bounces;
        p.bounce_ticks = std::max(o.switch_bounce_ticks != 0 ? o.switch_bounce_ticks : 4 * o.switch_bounces,
                                  2 * o.switch_bounces);
        p.seed = o.switch_seed + out.size();
        out.push_back(sw);
    }
    return out;
}

void place_sim_switches(sim::SimulatedMotionDevice& device, const std::vector<SimSwitch>& switches,
                        const MachineProfile& profile, const DeviceLog& log) {
    for (const SimSwitch& sw : switches) {
        const sim::SwitchPlacement& p = sw.placement;
        const hal::GpioLineLocation where = hal::locate_gpiod_line(linux_device::line_spec(profile.gpio.chip, sw.line));
        auto pull = std::make_shared<sim::GpioSimPull>(where.chip_name, where.offset, sw.line.active_low);
        device.switches().place(p, [pull](bool closed) { pull->set(closed); });
        char text[160];
        std::snprintf(text, sizeof text, "simulated switch %s at %.4f mm (hysteresis %.4f mm, %u bounces within %u ticks): ",
                      sw.name.c_str(), static_cast<double>(p.trigger) * profile.mm_per_lsb,
                      static_cast<double>(p.hysteresis) * profile.mm_per_lsb, p.bounces, p.bounce_ticks);
        log("gpio", text + pull->path());
    }
}

// Configuration, GPIO and homing from the profile, shared by every transport.
struct Machine {
    std::optional<MachineProfile> profile;
    std::optional<linux_device::MachineLines> lines;
    sim::DeviceIo* io = nullptr;
    std::optional<linux_device::HomingRunLog> homing_log;  ///< homing runs a bus command starts

    // After every tick while serving: the log's lines of a homing run.
    void after_tick(const DeviceLog& log) {
        if (homing_log) homing_log->after_tick([&log](const std::string& line) { log("homing", line); });
    }
};

Machine prepare_machine(sim::SimulatedMotionDevice& device, const DeviceCommandOptions& o,
                        const std::optional<MachineProfile>& profile, const DeviceLog& log,
                        DeviceWatch& watch) {
    Machine m;
    if (!profile) return m;
    m.profile = profile;
    const std::vector<SimSwitch> switches = read_sim_switches(o, *profile);
    const DeviceLimitsLsb limits = device_limits(*profile);
    if (Status s = device.configure(limits); s != Status::kOk) {
        throw std::invalid_argument(profile->source + ": the device refused the profile's limits: " + status_name(s));
    }
    std::string text =
        "configured from " + profile->source + ": " + std::to_string(limits.tick_hz) + " Hz ticks";
    for (std::size_t a = 0; a < profile->axes.size(); ++a) {
        text += ", " + profile->axes[a].name + " " + std::to_string(limits.max_velocity[a]) +
                " LSB/s " + std::to_string(limits.max_acceleration[a]) + " LSB/s^2";
        if (limits.max_jerk[a] != 0) {
            text += " " + std::to_string(std::uint64_t{limits.max_jerk[a]} * device::kJerkUnitLsb) + " LSB/s^3";
        }
    }
    log("configured", text, {{"tick_hz", limits.tick_hz}});
    if (profile->gpio.present && !o.no_gpio) {
        m.lines.emplace(linux_device::MachineLines::open(*profile));
        m.io = &device.attach_io(m.lines->wiring());
        log("gpio", "GPIO " + m.lines->summary());
        // The bus's home command homes these (pathstream ctl TARGET home).
        try {
            linux_device::set_homing_plan(*m.io, homing_setups(*profile));
        } catch (const linux_device::HomingFailed& e) {
            throw std::invalid_argument(profile->source + ": " + e.what());
        }
    }
    if (!switches.empty()) place_sim_switches(device, switches, *profile, log);
    if (o.home) {
        if (m.io == nullptr) {
            throw std::invalid_argument(profile->source + ": no \"gpio\" object: --home has no switches to home against");
        }
        if (profile->gpio.home.empty()) throw std::invalid_argument(profile->source + ": --home: gpio.home is empty");
        home(device, *m.io, *profile, o.time_scale, log, watch);
    }
    if (m.io != nullptr && !profile->gpio.home.empty()) {
        m.homing_log.emplace(device, *m.io, homing_setups(*profile), profile->mm_per_lsb);
    }
    return m;
}

// The pacing: `o`'s time scale; an idle device that has changed nothing for 1,000 ticks (any
// pen dwell or homing wait long over) ticks at most 1,000 times a second of wall time, so that
// its CPU does not grow with --time-scale. A request wakes it within a millisecond.
sim::DeviceLoopOptions loop_options(const DeviceCommandOptions& o, const sim::SimulatedMotionDevice& device) {
    sim::DeviceLoopOptions loop;
    loop.time_scale = o.time_scale;
    loop.run_for = std::chrono::milliseconds(static_cast<long>(o.exit_after * 1000));
    loop.at_rest = [&device] {
        return device.state() == static_cast<std::uint8_t>(device::DeviceState::kIdle) && device.unchanged_ticks() >= 1000;
    };
    return loop;
}

int run_can_device(const DeviceCommandOptions& o, const std::vector<Lsb>& start,
                   const std::optional<MachineProfile>& profile) {
    auto device = sim::SimulatedCanDevice::create(start, static_cast<std::uint8_t>(o.node));
    device->record(!o.record.empty());
    const DeviceLog log(o.log_json);
    DeviceWatch watch(log, status_reader(*device));
    Machine machine = prepare_machine(*device, o, profile, log, watch);
    hal::SocketCanBus bus(o.can_interface);
    const std::string url =
        "can://" + o.can_interface + "?node=" + std::to_string(o.node) + "&protocol=native";
    log("serving",
        std::to_string(device->axes()) + " axes, native CAN node " + std::to_string(o.node) +
            " on " + o.can_interface + " (" + url + ")",
        {{"url", url}, {"axes", device->axes()}});
    sim::run_paced_loop(
        [&] {
            device->tick();
            watch.after_tick(*device);
            machine.after_tick(log);
        },
        [&] { return device->tick_hz(); },
        [&](std::chrono::microseconds w) { device->serve(bus, w); }, loop_options(o, *device), g_stop);
    const hal::SocketCanCounters& c = bus.counters();
    log("stopped",
        "stopped after " + std::to_string(device->ticks_run()) + " ticks, " +
            std::to_string(c.frames_received) + " frames in, " + std::to_string(c.frames_sent) +
            " out, " + std::to_string(device->incomplete_transfers()) + " incomplete and " +
            std::to_string(device->refused_batches()) + " refused batches, " +
            std::to_string(c.error_frames) + " error frames",
        {{"ticks", device->ticks_run()}});
    if (!o.record.empty()) write_record(*device, o.record);
    return 0;
}

int run_modbus_device(const DeviceCommandOptions& o, const std::vector<Lsb>& start,
                      const std::optional<MachineProfile>& profile) {
    auto device = sim::SimulatedModbusDevice::create(start);
    device->record(!o.record.empty());
    const DeviceLog log(o.log_json);
    DeviceWatch watch(log, status_reader(*device));
    Machine machine = prepare_machine(*device, o, profile, log, watch);
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
    log("serving", std::to_string(device->axes()) + " axes, serving " + url,
        {{"url", url}, {"axes", device->axes()}});
    sim::run_paced_loop(
        [&] {
            device->tick();
            watch.after_tick(*device);
            machine.after_tick(log);
        },
        [&] { return device->tick_hz(); },
        [&](std::chrono::microseconds w) {
            server.poll_once(w);
            watch.after_poll(server);
        },
        loop_options(o, *device), g_stop);
    watch.after_poll(server, true);
    log("stopped",
        "stopped after " + std::to_string(device->ticks_run()) + " ticks, " +
            std::to_string(server.counters().requests.load()) + " requests (" +
            std::to_string(server.counters().exceptions.load()) + " refused)",
        {{"ticks", device->ticks_run()}, {"requests", server.counters().requests.load()}});
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
    cmd->add_flag(
        "--log-json", o.log_json,
        "print the log as NDJSON (one JSON object per line, docs/events.md) instead of text");
    cmd->add_option("--sim-switch", o.sim_switches,
                    "play the profile's limit switch NAME (e.g. x-) from the simulated axis on a gpio-sim chip: "
                    "closed at POSITION (mm, or LSB with the suffix lsb) and beyond; NAME=POSITION, repeatable "
                    "(docs/gpio.md)");
    cmd->add_option("--switch-hysteresis", o.switch_hysteresis,
                    "with --sim-switch: mm the axis moves back past the trigger before the switch opens")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 100.0));
    cmd->add_option("--switch-bounce", o.switch_bounces,
                    "with --sim-switch: times the contact opens and closes again after every change")
        ->capture_default_str()
        ->check(CLI::Range(0, 100));
    cmd->add_option("--switch-bounce-ticks", o.switch_bounce_ticks,
                    "with --sim-switch: ticks the bounces fall within (0: 4 x --switch-bounce; at least 2 x it)")
        ->capture_default_str()
        ->check(CLI::Range(0, 100000));
    cmd->add_option("--switch-seed", o.switch_seed, "with --sim-switch: seed of the bounces' ticks")->capture_default_str();
    cmd->callback([cmd, &o] {
        if (!o.sim_switches.empty() && o.machine.empty()) {
            throw CLI::ValidationError("--sim-switch", "needs --machine (the profile's gpio.limits)");
        }
        if (!o.sim_switches.empty() && o.no_gpio) {
            throw CLI::ValidationError("--sim-switch", "drives the profile's GPIO lines: not with --no-gpio");
        }
        for (const char* opt : {"--switch-hysteresis", "--switch-bounce", "--switch-bounce-ticks", "--switch-seed"}) {
            if (cmd->count(opt) > 0 && o.sim_switches.empty()) throw CLI::ValidationError(opt, "needs --sim-switch");
        }
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
            return kExitUsage;
        }
        const double mm_per_lsb = profile ? profile->mm_per_lsb : 0.001;
        for (unsigned a = 0; a < axes; ++a) start[a] = parse_position_argument(o.position[a], mm_per_lsb, "--position");
    }
    // Before homing: an interrupted homing must stop cleanly too.
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    if (!o.can_interface.empty()) return run_can_device(o, start, profile);
    return run_modbus_device(o, start, profile);
}

}  // namespace pathstream::host
