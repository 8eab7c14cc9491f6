#include "pathstream/linux_device/device_runtime.hpp"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "device_watch.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/linux_device/can_motion_device.hpp"
#include "pathstream/linux_device/machine_homing.hpp"
#include "pathstream/linux_device/machine_lines.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pathstream/linux_device/output_coils.hpp"
#include "pathstream/linux_device/paced_loop.hpp"
#include "pathstream/machine/atomic_file.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/shaper_design.hpp"

namespace pathstream::linux_device {
namespace {

void write_record(const AnyMotionDevice& d, const std::string& path) {
    host::AtomicFile f(path);
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

// Homes in real time (times --time-scale), before any bus is served: a host cannot start a
// job on a half-homed machine. `stop` ends homing at the next tick (HomingFailed); the lines
// are then released with enable and pen inactive (MachineLines).
void home(AnyMotionDevice& device, DeviceIo& io, const host::MachineProfile& profile,
          double time_scale, const DeviceLog& log, DeviceWatch& watch,
          const std::atomic<bool>& stop) {
    DeviceLoopOptions loop;
    loop.time_scale = time_scale;
    const auto run_until = [&](const std::function<bool()>& done) {
        std::atomic<bool> finished{false};
        run_paced_loop(
            [&] {
                device.tick();
                watch.after_tick(device);
                if (done() || stop.load()) finished.store(true);
            },
            [&] { return device.tick_hz(); },
            [](std::chrono::microseconds w) { std::this_thread::sleep_for(w); }, loop, finished);
        return done();
    };
    const auto phase = [&log](const std::string& line) { log("homing", line); };
    (void)home_axes(device, io, host::homing_setups(profile), profile.mm_per_lsb, run_until, phase);
}

// Configuration, GPIO, output coils and homing from the profile, shared by every transport.
struct Machine {
    std::optional<host::MachineProfile> profile;
    std::optional<MachineLines> lines;
    DeviceIo* io = nullptr;
    std::optional<HomingRunLog> homing_log;   ///< homing runs a bus command starts
    std::unique_ptr<OutputCoilThread> coils;  ///< the profile's output_coils

    // After every tick while serving: the machine outputs to the coil writer (a failed write
    // stops the machine), the log's lines of a homing run.
    void after_tick(AnyMotionDevice& device, const DeviceLog& log) {
        if (coils) {
            const std::string failure = coils->after_tick(device);
            if (!failure.empty()) log("outputs", failure + "; stopping the machine");
        }
        if (homing_log)
            homing_log->after_tick([&log](const std::string& line) { log("homing", line); });
    }

    // When the device stops serving: every coil off, said in the log.
    void stop_outputs(const DeviceLog& log) {
        if (!coils) return;
        const std::string failure = coils->stop();
        log("outputs", failure.empty() ? "output coils off" : failure);
    }
};

// Connects to the profile's output module and writes every coil off: the machine's outputs
// are known before anything is served. A module that cannot be reached or refuses the writes
// stops the start (hal::ModbusError, naming the profile and the target).
void open_output_coils(Machine& m, const host::MachineProfile& profile, const DeviceLog& log) {
    const std::string where = profile.source + ": output_coils: ";
    try {
        m.coils = std::make_unique<OutputCoilThread>(CoilWriter(profile.output_coils));
    } catch (const hal::ModbusError& e) {
        throw hal::ModbusError(e.kind(), where + e.what(), e.exception_code(), e.os_error());
    } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(where + e.what());
    }
    log("outputs",
        "output coils at " + m.coils->target() + ": " + m.coils->mapping() + "; all off");
}

/// The profile's input shapers on the device, one log line naming each axis's taps.
void configure_shaping(AnyMotionDevice& device, const host::MachineProfile& profile,
                       std::uint32_t tick_hz, const DeviceLog& log) {
    for (std::size_t a = 0; a < profile.input_shaper.size(); ++a) {
        if (!profile.input_shaper[a]) continue;
        const host::ShaperSpec& spec = *profile.input_shaper[a];
        const std::vector<ShaperTap> taps =
            host::design_shaper_taps(spec, tick_hz, host::kDeviceShaperHistoryTicks);
        if (Status s = device.configure_shaper(static_cast<unsigned>(a), taps, tick_hz);
            s != Status::kOk) {
            throw std::invalid_argument(profile.source +
                                        ": the device refused the input shaper of " +
                                        profile.axes[a].name + ": " + status_name(s));
        }
        std::ostringstream text;
        text << "input shaper on " << profile.axes[a].name << ": "
             << host::shaper_type_name(spec.type) << " at " << spec.frequency_hz << " Hz, damping "
             << spec.damping << ", " << taps.size() << " taps over " << taps.back().delay
             << " ticks";
        log("shaper", text.str(), {{"axis", profile.axes[a].name}, {"taps", taps.size()}});
    }
}

Machine prepare_machine(AnyMotionDevice& device, const DeviceRunOptions& o,
                        const std::optional<host::MachineProfile>& profile,
                        const AttachMachine& attach, const DeviceLog& log, DeviceWatch& watch,
                        const std::atomic<bool>& stop) {
    Machine m;
    if (!profile) return m;
    m.profile = profile;
    const host::DeviceLimitsLsb limits = host::device_limits(*profile);
    if (Status s = device.configure(limits); s != Status::kOk) {
        throw std::invalid_argument(profile->source +
                                    ": the device refused the profile's limits: " + status_name(s));
    }
    std::string text =
        "configured from " + profile->source + ": " + std::to_string(limits.tick_hz) + " Hz ticks";
    for (std::size_t a = 0; a < profile->axes.size(); ++a) {
        text += ", " + profile->axes[a].name + " " + std::to_string(limits.max_velocity[a]) +
                " LSB/s " + std::to_string(limits.max_acceleration[a]) + " LSB/s^2";
        if (limits.max_jerk[a] != 0) {
            text += " " + std::to_string(std::uint64_t{limits.max_jerk[a]} * device::kJerkUnitLsb) +
                    " LSB/s^3";
        }
    }
    log("configured", text, {{"tick_hz", limits.tick_hz}});
    configure_shaping(device, *profile, limits.tick_hz, log);
    if (profile->gpio.present && !o.no_gpio) {
        m.lines.emplace(MachineLines::open(*profile));
        m.io = &device.attach_io(m.lines->wiring());
        log("gpio", "GPIO " + m.lines->summary());
        // The bus's home command homes these (pathstream ctl TARGET home).
        try {
            set_homing_plan(*m.io, host::homing_setups(*profile));
        } catch (const HomingFailed& e) {
            throw std::invalid_argument(profile->source + ": " + e.what());
        }
    }
    if (profile->output_coils.present) open_output_coils(m, *profile, log);
    if (attach) attach(device, log);
    if (o.home) {
        if (m.io == nullptr) {
            throw std::invalid_argument(
                profile->source + ": no \"gpio\" object: --home has no switches to home against");
        }
        if (profile->gpio.home.empty())
            throw std::invalid_argument(profile->source + ": --home: gpio.home is empty");
        home(device, *m.io, *profile, o.time_scale, log, watch, stop);
    }
    if (m.io != nullptr && !profile->gpio.home.empty()) {
        m.homing_log.emplace(device, *m.io, host::homing_setups(*profile), profile->mm_per_lsb);
    }
    return m;
}

// The pacing: `o`'s time scale; an idle device that has changed nothing for 1,000 ticks (any
// pen dwell or homing wait long over) ticks at most 1,000 times a second of wall time, so that
// its CPU does not grow with --time-scale. A request wakes it within a millisecond.
DeviceLoopOptions loop_options(const DeviceRunOptions& o, const AnyMotionDevice& device) {
    DeviceLoopOptions loop;
    loop.time_scale = o.time_scale;
    loop.run_for = std::chrono::milliseconds(static_cast<long>(o.exit_after * 1000));
    loop.at_rest = [&device] {
        return device.state() == device::DeviceState::kIdle && device.unchanged_ticks() >= 1000;
    };
    return loop;
}

// Ticks the device (its log and homing lines after every tick) and serves its bus in between,
// paced by loop_options, until `stop` or the time given.
void serve_until_stopped(AnyMotionDevice& device, DeviceWatch& watch, Machine& machine,
                         const DeviceLog& log,
                         const std::function<void(std::chrono::microseconds)>& serve,
                         const DeviceRunOptions& o, const std::atomic<bool>& stop) {
    run_paced_loop(
        [&] {
            device.tick();
            watch.after_tick(device);
            machine.after_tick(device, log);
        },
        [&] { return device.tick_hz(); }, serve, loop_options(o, device), stop);
}

int run_can_device(const DeviceRunOptions& o, const std::vector<Lsb>& start,
                   const std::optional<host::MachineProfile>& profile, const AttachMachine& attach,
                   const std::atomic<bool>& stop) {
    auto device = CanMotionDevice::create(start, static_cast<std::uint8_t>(o.node));
    device->record(!o.record.empty());
    const DeviceLog log(o.log_json);
    DeviceWatch watch(log, status_reader(*device));
    Machine machine = prepare_machine(*device, o, profile, attach, log, watch, stop);
    hal::SocketCanBus bus(o.can_interface);
    const std::string url =
        "can://" + o.can_interface + "?node=" + std::to_string(o.node) + "&protocol=native";
    log("serving",
        std::to_string(device->axes()) + " axes, native CAN node " + std::to_string(o.node) +
            " on " + o.can_interface + " (" + url + ")",
        {{"url", url}, {"axes", device->axes()}});
    serve_until_stopped(
        *device, watch, machine, log, [&](std::chrono::microseconds w) { device->serve(bus, w); },
        o, stop);
    machine.stop_outputs(log);
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

int run_modbus_device(const DeviceRunOptions& o, const std::vector<Lsb>& start,
                      const std::optional<host::MachineProfile>& profile,
                      const AttachMachine& attach, const std::atomic<bool>& stop) {
    auto device = ModbusMotionDevice::create(start);
    device->record(!o.record.empty());
    const DeviceLog log(o.log_json);
    DeviceWatch watch(log, status_reader(*device));
    Machine machine = prepare_machine(*device, o, profile, attach, log, watch, stop);
    hal::ModbusServerOptions server_options;
    server_options.unit = o.unit;
    std::string url;
    auto server = [&]() -> hal::ModbusServer {
        if (o.rtu_pty || !o.rtu_device.empty()) {
            hal::ModbusServer s =
                o.rtu_pty ? hal::ModbusServer::rtu_pty(device->handler(), server_options)
                          : hal::ModbusServer::rtu(device->handler(),
                                                   {o.rtu_device, o.baud, o.parity[0], 8, 1},
                                                   server_options);
            url = "modbus-rtu://" + s.client_device() + "?baud=" + std::to_string(o.baud) +
                  "&parity=" + o.parity + "&unit=" + std::to_string(o.unit);
            return s;
        }
        const auto colon = o.tcp.rfind(':');
        if (colon == std::string::npos)
            throw std::invalid_argument("--tcp wants HOST:PORT, not '" + o.tcp + "'");
        hal::ModbusTcpEndpoint endpoint;
        endpoint.host = o.tcp.substr(0, colon);
        const int port = std::stoi(o.tcp.substr(colon + 1));
        if (port < 0 || port > 65535)
            throw std::invalid_argument("--tcp port out of range: " + o.tcp);
        endpoint.port = static_cast<std::uint16_t>(port);
        hal::ModbusServer s = hal::ModbusServer::tcp(device->handler(), endpoint, server_options);
        url = "modbus-tcp://" + endpoint.host + ":" + std::to_string(s.port()) +
              "?unit=" + std::to_string(o.unit);
        return s;
    }();
    log("serving", std::to_string(device->axes()) + " axes, serving " + url,
        {{"url", url}, {"axes", device->axes()}});
    serve_until_stopped(
        *device, watch, machine, log,
        [&](std::chrono::microseconds w) {
            server.poll_once(w);
            watch.after_poll(server);
        },
        o, stop);
    machine.stop_outputs(log);
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

int run_device_runtime(const DeviceRunOptions& options, const std::vector<Lsb>& start,
                       const std::optional<host::MachineProfile>& profile,
                       const AttachMachine& attach, const std::atomic<bool>& stop) {
    if (!options.can_interface.empty())
        return run_can_device(options, start, profile, attach, stop);
    return run_modbus_device(options, start, profile, attach, stop);
}

}  // namespace pathstream::linux_device
