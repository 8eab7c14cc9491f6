#include "stream_command.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <string>

#include "pathstream/hal/socketcan_bus.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/cia402_master.hpp"
#include "pathstream/host/progress.hpp"
#include "plan_command.hpp"

namespace pathstream::host {

void add_stream_command(CLI::App& app, StreamCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand("stream",
                                       "Plan the path and stream it to a device running the core "
                                       "over Modbus TCP or RTU (docs/modbus.md) or native "
                                       "CAN (docs/can.md), or to CiA 402 drives in cyclic "
                                       "synchronous position mode (docs/cia402.md)");
    add_path_options(*cmd, o.path);
    cmd->add_option("--machine,-m", o.machine, "machine profile (JSON, docs/formats.md)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--target,-t", o.stream.target,
                    "device: modbus-tcp://HOST:PORT?unit=N, "
                    "modbus-rtu:///dev/ttyX?baud=115200&parity=N&unit=1, "
                    "can://IFACE?node=N&protocol=native or CiA 402 drives "
                    "can://IFACE?node=N&protocol=cia402&cycle=2ms")
        ->required();
    cmd->add_flag("--lead-in", o.lead_in,
                  "start with a pen-up move from where the device rests (e.g. after homing) to the drawing's first "
                  "point (Modbus targets: their status carries the position)");
    cmd->add_option("--lead", o.stream.lead_seconds,
                    "seconds of motion kept queued ahead of the device (Modbus, native CAN)")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 60.0));
    cmd->add_option("--timeout-ms", o.stream.response_timeout_ms,
                    "response timeout per Modbus try (native CAN: wait for an answer before "
                    "resending, at most 100)")
        ->capture_default_str()
        ->check(CLI::Range(10u, 60000u));
    cmd->add_option("--attempts", o.stream.attempts,
                    "tries per Modbus transaction before reconnecting")
        ->capture_default_str()
        ->check(CLI::Range(1u, 100u));
    cmd->add_option("--link-timeout", o.stream.link_timeout_seconds,
                    "give up after this many seconds without an answer (Modbus, native CAN)")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 3600.0));
}

// ---- CAN targets (docs/can.md): can://IFACE?node=N&protocol=native|cia402 ----------------
namespace {

int run_stream_can(const StreamCommandOptions& o, const PlannedJob& job) {
    if (o.stream.target.find("protocol=cia402") != std::string::npos) {  // its own keys (cycle=...): docs/cia402.md
        hal::SocketCanBus cia402_bus(parse_cia402_target(o.stream.target, job.machine.axes.size()).interface);
        return run_cia402_stream(job.plan, job.machine, o.stream.target, cia402_bus);
    }
    const CanTarget t = parse_can_target(o.stream.target);
    hal::SocketCanBus bus(t.interface_name);
    CanStreamOptions c;
    c.node = t.node;
    c.name = o.stream.target;
    c.lead_seconds = o.stream.lead_seconds;
    c.ack_timeout_ms = std::min(o.stream.response_timeout_ms, 100u);
    c.link_timeout_seconds = o.stream.link_timeout_seconds;
    CanStreamReport r;
    {
        ProgressBar bar("streaming");
        r = stream_can(job.plan, job.machine, bus, c, [&](double fraction, double queued) {
            char detail[48];
            std::snprintf(detail, sizeof detail, "queue %.2f s", queued);
            bar.update(fraction, detail);
        });
    }
    const double motion = static_cast<double>(r.ticks_executed) / job.machine.tick_hz;
    std::printf("streamed      %s (native CAN protocol, node %u)\n", o.stream.target.c_str(), unsigned(t.node));
    std::printf("executed      %llu ticks (%.3f s of motion), %llu spans in %llu batches, last span %u\n",
                static_cast<unsigned long long>(r.ticks_executed), motion,
                static_cast<unsigned long long>(r.spans_sent), static_cast<unsigned long long>(r.batches),
                r.last_completed);
    std::printf("job           %u finished: the device is idle at the drawing's end point\n", r.job);
    std::printf("bus           %llu frames sent, %llu received, %llu retransmitted batches, %llu timeouts;"
                " %.1f kbit/s worst case (%.2f %% of 1 Mbit/s)\n",
                static_cast<unsigned long long>(r.frames_sent), static_cast<unsigned long long>(r.frames_received),
                static_cast<unsigned long long>(r.retransmissions), static_cast<unsigned long long>(r.timeouts),
                static_cast<double>(r.bits_sent + r.bits_received) / motion / 1e3,
                static_cast<double>(r.bits_sent + r.bits_received) / motion / 1e4);
    std::printf("device        %u underruns, %u duplicate batches acknowledged; wall time %.2f s\n", r.underruns,
                r.duplicates, r.wall_seconds);
    return 0;
}

}  // namespace

int run_stream(const StreamCommandOptions& o) {
    const std::string& url = o.stream.target;
    if (url.rfind("modbus-tcp://", 0) != 0 && url.rfind("modbus-rtu://", 0) != 0 &&
        url.rfind("can://", 0) != 0) {
        throw std::invalid_argument(
            "bad target URL '" + url +
            "': unknown scheme (want modbus-tcp://, modbus-rtu:// or can://)");
    }
    std::vector<double> rest_mm;
    if (o.lead_in) {
        if (o.stream.target.rfind("can://", 0) == 0) {
            throw std::invalid_argument("--lead-in needs a Modbus target: the CAN status carries no position");
        }
        const MachineProfile machine = load_machine_profile(o.machine);
        for (const Lsb p : modbus_rest_position(machine, o.stream)) rest_mm.push_back(p * machine.mm_per_lsb);
        std::printf("lead-in       from the device's rest position");
        for (std::size_t a = 0; a < rest_mm.size(); ++a) {
            std::printf(" %s %.4f mm", machine.axes[a].name.c_str(), rest_mm[a]);
        }
        std::printf("\n");
    }
    const PlannedJob job = plan_job(o.path, o.machine, o.lead_in ? &rest_mm : nullptr);
    if (o.stream.target.rfind("can://", 0) == 0) return run_stream_can(o, job);
    StreamReport r;
    {
        ProgressBar bar("streaming");
        r = stream_modbus(job.plan, job.machine, o.stream, [&](double fraction, double queued) {
            char detail[48];
            std::snprintf(detail, sizeof detail, "queue %.2f s", queued);
            bar.update(fraction, detail);
        });
    }
    std::printf("streamed      %s\n", o.stream.target.c_str());
    std::printf("executed      %llu ticks (%.3f s of motion), %llu spans in %llu batches, last span %u\n",
                static_cast<unsigned long long>(r.ticks_executed), static_cast<double>(r.ticks_executed) / job.machine.tick_hz,
                static_cast<unsigned long long>(r.spans_sent), static_cast<unsigned long long>(r.batches), r.last_completed);
    std::printf("job           %u finished: the device is idle at the drawing's end point\n", r.job);
    std::printf("final point  ");
    for (std::size_t a = 0; a < job.machine.axes.size(); ++a) {
        std::printf(" %s %.4f mm", job.machine.axes[a].name.c_str(), r.final_position[a] * job.machine.mm_per_lsb);
    }
    std::printf("\nlink          %llu transactions, %llu retries, %llu reconnects, %llu bytes sent, %llu received"
                " (%.0f B per s of motion)\n",
                static_cast<unsigned long long>(r.transactions), static_cast<unsigned long long>(r.retries),
                static_cast<unsigned long long>(r.reconnects), static_cast<unsigned long long>(r.bytes_sent),
                static_cast<unsigned long long>(r.bytes_received),
                (r.bytes_sent + r.bytes_received) / (static_cast<double>(r.ticks_executed) / job.machine.tick_hz));
    std::printf("device        %u underruns, %u duplicate batches acknowledged; wall time %.2f s\n", r.underruns,
                r.duplicates, r.wall_seconds);
    return 0;
}

}  // namespace pathstream::host
