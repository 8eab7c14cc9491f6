#include "device_command.hpp"

#include <atomic>
#include <csignal>
#include <iostream>
#include <stdexcept>

#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/sim/can_device.hpp"
#include "pathstream/host/atomic_file.hpp"
#include "pathstream/sim/modbus_device.hpp"

namespace pathstream::host {
namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_signal(int) { g_stop.store(true); }

template <typename Device>
void write_record_any(const Device& d, const std::string& path) {
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

// ---- native CAN (docs/can.md): --can IFACE --node N ---------------------------------------
// Kept here, not in DeviceCommandOptions, so this addition stays in this file.
struct CanDeviceOptions {
    std::string interface_name;
    unsigned node = 1;
};
CanDeviceOptions g_can;

int run_can_device(const DeviceCommandOptions& o, const std::vector<Lsb>& start) {
    auto device = sim::SimulatedCanDevice::create(start, static_cast<std::uint8_t>(g_can.node));
    device->record(!o.record.empty());
    hal::SocketCanBus bus(g_can.interface_name);
    std::cout << "pathstream device: " << o.axes << " axes, native CAN node " << g_can.node << " on "
              << g_can.interface_name << " (can://" << g_can.interface_name << "?node=" << g_can.node
              << "&protocol=native)" << std::endl;
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    sim::DeviceLoopOptions loop;
    loop.time_scale = o.time_scale;
    loop.run_for = std::chrono::milliseconds(static_cast<long>(o.exit_after * 1000));
    const std::uint64_t ticks = sim::run_can_device_loop(*device, bus, loop, g_stop);
    const hal::SocketCanCounters& c = bus.counters();
    std::cout << "pathstream device: stopped after " << ticks << " ticks, " << c.frames_received << " frames in, "
              << c.frames_sent << " out, " << device->incomplete_transfers() << " incomplete and "
              << device->refused_batches() << " refused batches, " << c.error_frames << " error frames" << std::endl;
    if (!o.record.empty()) write_record_any(*device, o.record);
    return 0;
}

}  // namespace

void add_device_command(CLI::App& app, DeviceCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "device", "Run the simulated device (the firmware core) as a Modbus TCP or RTU server (docs/modbus.md)");
    cmd->add_option("--axes", o.axes, "axis count")->capture_default_str()->check(CLI::Range(1, 8));
    cmd->add_option("--position", o.position, "initial position, LSB per axis (default 0)")->delimiter(',');
    cmd->add_option("--tcp", o.tcp, "serve Modbus TCP on HOST:PORT (port 0: any free port)")->capture_default_str();
    cmd->add_flag("--rtu-pty", o.rtu_pty, "serve Modbus RTU on a new pseudo-terminal (prints its path)");
    cmd->add_option("--rtu", o.rtu_device, "serve Modbus RTU on this serial device");
    cmd->add_option("--baud", o.baud, "RTU baud rate")->capture_default_str();
    cmd->add_option("--parity", o.parity, "RTU parity")->capture_default_str()->check(CLI::IsMember({"N", "E", "O"}));
    cmd->add_option("--unit", o.unit, "RTU unit id")->capture_default_str()->check(CLI::Range(1, 247));
    cmd->add_option("--time-scale", o.time_scale, "run ticks this many times faster than real time")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 1000.0));
    cmd->add_option("--record", o.record, "write every executed path tick to this CSV (tick,x,y,...,pen) at exit");
    cmd->add_option("--can", g_can.interface_name, "serve the native CAN protocol on this SocketCAN interface (docs/can.md)");
    cmd->add_option("--node", g_can.node, "CAN node id (with --can)")->capture_default_str()->check(CLI::Range(1, 127));
    cmd->add_option("--exit-after", o.exit_after, "stop after this many seconds (default: at SIGINT/SIGTERM)")
        ->check(CLI::Range(0.0, 1e6));
}

int run_device(const DeviceCommandOptions& o) {
    std::vector<Lsb> start(o.axes, 0);
    if (!o.position.empty()) {
        if (o.position.size() != o.axes) {
            std::cerr << "pathstream device: --position has " << o.position.size() << " values for " << o.axes
                      << " axes\n";
            return 2;
        }
        for (unsigned a = 0; a < o.axes; ++a) start[a] = o.position[a];
    }
    if (!g_can.interface_name.empty()) return run_can_device(o, start);
    auto device = sim::SimulatedModbusDevice::create(start);
    device->record(!o.record.empty());
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
    std::cout << "pathstream device: " << o.axes << " axes, serving " << url << std::endl;
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    sim::DeviceLoopOptions loop;
    loop.time_scale = o.time_scale;
    loop.run_for = std::chrono::milliseconds(static_cast<long>(o.exit_after * 1000));
    const std::uint64_t ticks =
        sim::run_device_loop(*device, [&](std::chrono::milliseconds w) { server.poll_once(w); }, loop, g_stop);
    std::cout << "pathstream device: stopped after " << ticks << " ticks, " << server.counters().requests.load()
              << " requests (" << server.counters().exceptions.load() << " refused)" << std::endl;
    if (!o.record.empty()) write_record_any(*device, o.record);
    return 0;
}

}  // namespace pathstream::host
