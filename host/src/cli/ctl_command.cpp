#include "ctl_command.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "pathstream/device/operator_commands.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/machine/position_argument.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host {
namespace {

// The spindle output as the status reports it.
const char* spindle_text(unsigned outputs) {
    if ((outputs & kOutputSpindle) == 0) return "off";
    return (outputs & kOutputSpindleReverse) != 0 ? "counter-clockwise" : "clockwise";
}

using Clock = std::chrono::steady_clock;

std::atomic<bool> g_interrupted{false};
extern "C" void on_ctl_signal(int) {
    g_interrupted.store(true);
}

struct VerbInfo {
    const char* verb;
    device::Command command;
};
constexpr VerbInfo kVerbs[] = {{"hold", device::Command::kHold},
                               {"resume", device::Command::kResume},
                               {"stop", device::Command::kStop},
                               {"reset", device::Command::kReset}};

// The axis names and mm scale, from the profile when one was given.
struct Units {
    std::optional<MachineProfile> profile;
    std::string axis_name(unsigned a) const {
        static const char* const names[] = {"x", "y", "z", "a", "b", "c", "u", "v"};
        return profile && a < profile->axes.size() ? profile->axes[a].name : names[a % 8];
    }
};

std::string flags_text(const DeviceSnapshot& s) {
    std::string t = s.configured() ? "configured" : "not configured";
    if (s.held_by_underrun()) t += ", held by underrun";
    if (s.homing_runs()) t += ", homing";
    if (s.paused()) t += ", paused (a programmed pause: resume goes on)";
    return t;
}

// The --wait of a command, or its default.
double wait_seconds(const CtlCommandOptions& o, double fallback) {
    return o.wait_seconds >= 0 ? o.wait_seconds : fallback;
}

// "x homed, y not homed" (with the reason of a failure).
std::string homing_text(const DeviceSnapshot& s, const Units& u) {
    std::string t;
    for (unsigned a = 0; a < s.axes && a < kMaxAxes; ++a) {
        if (a) t += ", ";
        t += u.axis_name(a) + " " + axis_homing_name(s.homing[a].state);
        if (s.homing[a].state == device::AxisHoming::kFailed) {
            t += std::string(" (") + homing_error_name(s.homing[a].error) + ")";
        }
    }
    return t;
}

nlohmann::json to_json(const DeviceSnapshot& s, const Units& u, const std::string& target) {
    nlohmann::json j;
    j["target"] = target;
    j["protocol_version"] = s.version;
    j["axes"] = s.axes;
    j["state"] = device_state_name(s.state);
    j["state_code"] = s.state;
    j["fault_code"] = s.fault_code;
    j["fault"] = s.fault_code == 0 ? "none" : fault_text(s.fault_code);
    j["configured"] = s.configured();
    j["held_by_underrun"] = s.held_by_underrun();
    j["homing"] = s.homing_runs();
    j["paused"] = s.paused();
    j["pen_down"] = s.pen_down();
    j["spindle"] = spindle_text(s.outputs);
    j["mist"] = (s.outputs & kOutputMist) != 0;
    j["flood"] = (s.outputs & kOutputFlood) != 0;
    j["queued_spans"] = s.queued;
    j["free_slots"] = s.free_slots;
    j["ticks_executed"] = s.ticks_executed;
    j["last_accepted_sequence"] = s.last_accepted;
    j["last_completed_sequence"] = s.last_completed;
    j["finished_job"] = s.finished_job;
    j["finished_job_ticks"] = s.finished_job_ticks;
    j["epoch"] = s.epoch;
    j["underruns"] = s.underruns;
    j["duplicates"] = s.duplicates;
    nlohmann::json axes = nlohmann::json::array();
    for (unsigned a = 0; a < s.axes && a < kMaxAxes; ++a) {
        nlohmann::json axis{{"name", u.axis_name(a)},
                            {"position_lsb", s.position[a]},
                            {"homing", axis_homing_name(s.homing[a].state)}};
        if (s.homing[a].state == device::AxisHoming::kFailed)
            axis["homing_error"] = homing_error_name(s.homing[a].error);
        if (u.profile) axis["position_mm"] = s.position[a] * u.profile->mm_per_lsb;
        axes.push_back(axis);
    }
    j["position"] = axes;
    return j;
}

std::string position_text(const DeviceSnapshot& s, const Units& u) {
    std::ostringstream m;
    m.setf(std::ios::fixed);
    m.precision(4);
    for (unsigned a = 0; a < s.axes && a < kMaxAxes; ++a) {
        m << (a ? "  " : "") << u.axis_name(a) << ' ';
        if (u.profile) {
            m << s.position[a] * u.profile->mm_per_lsb << " mm (" << s.position[a] << " LSB)";
        } else {
            m << s.position[a] << " LSB";
        }
    }
    return m.str();
}

void print_status(const DeviceSnapshot& s, const Units& u, const std::string& target) {
    std::printf("device        %s (protocol %u, %u axes, %s)\n", target.c_str(), s.version, s.axes,
                flags_text(s).c_str());
    std::printf("state         %s%s\n", device_state_name(s.state),
                fault_suffix(s.state, s.fault_code).c_str());
    std::printf("queue         %u spans queued, %u slots free\n", s.queued, s.free_slots);
    std::printf("position      %s\n", position_text(s, u).c_str());
    std::printf("pen           %s\n", s.pen_down() ? "down" : "up");
    if ((s.outputs & kOutputMachineMask) != 0) {
        std::printf("machine       spindle %s%s%s\n", spindle_text(s.outputs),
                    (s.outputs & kOutputMist) != 0 ? ", mist" : "",
                    (s.outputs & kOutputFlood) != 0 ? ", flood" : "");
    }
    std::printf("homing        %s\n", homing_text(s, u).c_str());
    std::printf(
        "ticks         %u path ticks executed; spans: last accepted %u, last completed %u\n",
        s.ticks_executed, s.last_accepted, s.last_completed);
    if (s.finished_job != 0) {
        std::printf("job           last finished: job %u (%u path ticks)\n", s.finished_job,
                    s.finished_job_ticks);
    } else {
        std::printf("job           none finished yet\n");
    }
    std::printf("counters      epoch %u, %u underruns, %u duplicate batches\n", s.epoch,
                s.underruns, s.duplicates);
}

// One line per read for --watch: the fields that change.
void print_watch_line(const DeviceSnapshot& s, const Units& u) {
    std::printf("%-8s queue %3u  ticks %10u  last span %8u  %s\n", device_state_name(s.state),
                s.queued, s.ticks_executed, s.last_completed, position_text(s, u).c_str());
    std::fflush(stdout);
}

int run_status(DeviceLink& link, const CtlCommandOptions& o, const Units& u) {
    if (o.watch_seconds <= 0) {
        const DeviceSnapshot s = link.status();
        if (o.json) {
            std::printf("%s\n", to_json(s, u, link.name()).dump(2).c_str());
        } else {
            print_status(s, u, link.name());
        }
        return 0;
    }
    std::signal(SIGINT, on_ctl_signal);
    std::signal(SIGTERM, on_ctl_signal);
    for (unsigned n = 0; !g_interrupted.load() && (o.count == 0 || n < o.count); ++n) {
        if (n > 0) std::this_thread::sleep_for(std::chrono::duration<double>(o.watch_seconds));
        if (g_interrupted.load()) break;
        const DeviceSnapshot s = link.status();
        if (o.json) {
            std::printf("%s\n", to_json(s, u, link.name()).dump().c_str());  // NDJSON: one per line
            std::fflush(stdout);
        } else {
            print_watch_line(s, u);
        }
    }
    return 0;
}

// Whether the device has reached what command `c` leads to (a hold: holding at rest needs
// the stop to end, which the status does not say; holding is enough to stop waiting).
bool settled(device::Command c, const DeviceSnapshot& s) {
    using device::DeviceState;
    const auto st = static_cast<DeviceState>(s.state);
    switch (c) {
        case device::Command::kHold:
            return st != DeviceState::kRunning;
        case device::Command::kResume:
            return st != DeviceState::kHolding;
        case device::Command::kStop:
            return st != DeviceState::kRunning && st != DeviceState::kStopping &&
                   st != DeviceState::kHolding;
        case device::Command::kReset:
            return st == DeviceState::kIdle;
        default:
            return true;
    }
}

int run_command(DeviceLink& link, device::Command c, const CtlCommandOptions& o, const Units& u) {
    const DeviceSnapshot before = link.status();
    const Status r = link.command(c);
    if (r != Status::kOk) {
        std::ostringstream m;
        m << link.name() << ": device refused " << command_verb(c) << " while "
          << device_state_name(before.state) << fault_suffix(before.state, before.fault_code)
          << ": " << status_name(r);
        throw StreamError(m.str());
    }
    DeviceSnapshot s = link.status();
    const double wait = wait_seconds(o, 5);
    const auto deadline = Clock::now() + std::chrono::duration<double>(wait);
    while (!settled(c, s) && Clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        s = link.status();
    }
    if (o.json) {
        nlohmann::json j;
        j["command"] = command_verb(c);
        j["accepted"] = true;
        j["state_before"] = device_state_name(before.state);
        j["settled"] = settled(c, s);
        j["status"] = to_json(s, u, link.name());
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("%-13s accepted: %s -> %s%s\n", command_verb(c),
                    device_state_name(before.state), device_state_name(s.state),
                    fault_suffix(s.state, s.fault_code).c_str());
        std::printf("position      %s\n", position_text(s, u).c_str());
    }
    if (!settled(c, s)) {
        std::ostringstream m;
        m << link.name() << ": " << command_verb(c) << " accepted, but the device is still "
          << device_state_name(s.state) << " after " << wait << " s";
        throw StreamError(m.str());
    }
    return 0;
}

// An axis by name (with a profile) or by index.
unsigned axis_argument(const std::string& text, const Units& u, unsigned axes) {
    if (u.profile) {
        for (unsigned a = 0; a < u.profile->axes.size(); ++a) {
            if (u.profile->axes[a].name == text) return a;
        }
    }
    std::size_t used = 0;
    unsigned long index = 0;
    try {
        index = std::stoul(text, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != text.size() || index >= axes) {
        throw std::invalid_argument("ctl: no axis '" + text + "'" +
                                    (u.profile ? " in the profile"
                                               : " (an index 0.." + std::to_string(axes - 1) +
                                                     ", or a name with --machine)"));
    }
    return static_cast<unsigned>(index);
}

// Waits until the device has run job `job` to its end (idle, finished_job), or stopped.
DeviceSnapshot wait_for_job(DeviceLink& link, std::uint32_t job, double seconds) {
    const auto deadline = Clock::now() + std::chrono::duration<double>(seconds);
    DeviceSnapshot s = link.status();
    while (!(s.state == device::DeviceState::kIdle && s.finished_job == job) &&
           s.state != device::DeviceState::kFault && s.state != device::DeviceState::kEstop &&
           Clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        s = link.status();
    }
    return s;
}

// jog AXIS DISTANCE [--feed MM/S]: a move the device plans and checks itself.
int run_jog(DeviceLink& link, const CtlCommandOptions& o, const Units& u) {
    if (o.arguments.size() != 2)
        throw std::invalid_argument("ctl jog: want AXIS DISTANCE (mm, or LSB with lsb)");
    const DeviceSnapshot before = link.status();
    const unsigned axis = axis_argument(o.arguments[0], u, before.axes);
    if (!u.profile && !is_lsb_argument(o.arguments[1])) {
        throw std::invalid_argument(
            "ctl jog: a distance in mm needs --machine (or give LSB: 500lsb)");
    }
    const Lsb distance =
        parse_position_argument(o.arguments[1], u.profile ? u.profile->mm_per_lsb : 1.0, "ctl jog");
    if (distance == 0) throw std::invalid_argument("ctl jog: the distance is 0");
    std::uint16_t feed = 0;
    if (o.feed > 0) {
        if (!u.profile)
            throw std::invalid_argument("ctl jog: --feed needs --machine (its axis limits)");
        const double share = o.feed / u.profile->axes[axis].max_velocity;
        if (share > 1.0 + 1e-9) {
            throw std::invalid_argument(
                "ctl jog: --feed " + std::to_string(o.feed) + " mm/s is above the axis's " +
                std::to_string(u.profile->axes[axis].max_velocity) + " mm/s");
        }
        feed = static_cast<std::uint16_t>(std::clamp(std::lround(share * 1000.0), 1L, 1000L));
    }
    const Status r = link.command_with_arguments(device::kCommandJog, axis, distance, feed);
    if (r != Status::kOk) {
        throw StreamError(link.name() + ": device refused the jog while " +
                          device_state_name(before.state) +
                          fault_suffix(before.state, before.fault_code) + ": " + status_name(r));
    }
    // --wait 0: the jog is started and left to run (a script holds or stops it next).
    const bool no_wait = wait_seconds(o, 5) == 0;
    const DeviceSnapshot s =
        no_wait ? link.status() : wait_for_job(link, before.last_accepted + 1, wait_seconds(o, 5));
    const bool done =
        s.state == device::DeviceState::kIdle && s.finished_job == before.last_accepted + 1;
    if (o.json) {
        nlohmann::json j;
        j["command"] = "jog";
        j["axis"] = u.axis_name(axis);
        j["distance_lsb"] = distance;
        j["feed_per_mille"] = feed == 0 ? 1000 : feed;
        j["finished"] = done;
        j["ticks"] = s.finished_job_ticks;
        j["status"] = to_json(s, u, link.name());
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        if (no_wait && !done) {
            std::printf("jog           %s by %d LSB: started (--wait 0: not waited for)\n",
                        u.axis_name(axis).c_str(), distance);
        } else {
            std::printf("jog           %s by %d LSB: %s in %u ticks\n", u.axis_name(axis).c_str(),
                        distance, done ? "done" : "NOT done", s.finished_job_ticks);
        }
        std::printf("position      %s\n", position_text(s, u).c_str());
    }
    if (!done && !no_wait) {
        throw StreamError(link.name() + ": the jog did not finish within " +
                          std::to_string(wait_seconds(o, 5)) + " s: the device is " +
                          device_state_name(s.state) + fault_suffix(s.state, s.fault_code));
    }
    return 0;
}

// position AXIS VALUE: redefines the axis's coordinate at rest (idle only).
int run_set_position(DeviceLink& link, const CtlCommandOptions& o, const Units& u) {
    if (o.arguments.size() != 2)
        throw std::invalid_argument("ctl position: want AXIS VALUE (mm, or LSB with lsb)");
    const DeviceSnapshot before = link.status();
    const unsigned axis = axis_argument(o.arguments[0], u, before.axes);
    if (!u.profile && !is_lsb_argument(o.arguments[1])) {
        throw std::invalid_argument(
            "ctl position: a value in mm needs --machine (or give LSB: 12500lsb)");
    }
    const Lsb value = parse_position_argument(
        o.arguments[1], u.profile ? u.profile->mm_per_lsb : 1.0, "ctl position");
    const Status r = link.command_with_arguments(device::kCommandSetPosition, axis, value, 0);
    if (r != Status::kOk) {
        throw StreamError(link.name() + ": device refused set position while " +
                          device_state_name(before.state) +
                          fault_suffix(before.state, before.fault_code) + ": " + status_name(r));
    }
    DeviceSnapshot s = link.status();
    const auto deadline = Clock::now() + std::chrono::duration<double>(wait_seconds(o, 5));
    while (s.position[axis] != value && Clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        s = link.status();
    }
    if (o.json) {
        std::printf("%s\n", to_json(s, u, link.name()).dump(2).c_str());
    } else {
        std::printf("position      %s\n", position_text(s, u).c_str());
    }
    if (s.position[axis] != value)
        throw StreamError(link.name() + ": the device did not take the new position");
    return 0;
}

// home [AXES]: the device homes the axes (all it can: none named) one after another against
// their switches, each with its homing sequence; progress is printed as each axis's state
// changes.
int run_home(DeviceLink& link, const CtlCommandOptions& o, const Units& u) {
    const DeviceSnapshot before = link.status();
    unsigned mask = 0;
    for (const std::string& list : o.arguments) {
        std::size_t from = 0;
        while (from <= list.size()) {
            const std::size_t comma = std::min(list.find(',', from), list.size());
            const std::string name = list.substr(from, comma - from);
            if (!name.empty()) mask |= 1u << axis_argument(name, u, before.axes);
            from = comma + 1;
        }
    }
    const Status r = link.command_with_arguments(device::kCommandHome, mask, 0, 0);
    if (r != Status::kOk) {
        throw StreamError(link.name() + ": device refused home while " +
                          device_state_name(before.state) +
                          fault_suffix(before.state, before.fault_code) + ": " + status_name(r));
    }
    const double wait = wait_seconds(o, 300);
    const auto deadline = Clock::now() + std::chrono::duration<double>(wait);
    DeviceSnapshot s = link.status();
    device::HomingReport shown[kMaxAxes];
    std::copy(before.homing, before.homing + kMaxAxes, shown);
    const auto show_changes = [&] {
        for (unsigned a = 0; a < s.axes && a < kMaxAxes; ++a) {
            if (s.homing[a].state == shown[a].state && s.homing[a].error == shown[a].error)
                continue;
            shown[a] = s.homing[a];
            if (!o.json) {
                std::printf("home          %s %s\n", u.axis_name(a).c_str(),
                            axis_homing_name(s.homing[a].state));
                std::fflush(stdout);
            }
        }
    };
    // A homing run that is started shows in the very next status; one that was over before
    // the first read (an axis already on a stuck switch) shows in its reports.
    while (s.homing_runs() && !g_interrupted.load() && Clock::now() < deadline) {
        show_changes();
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        s = link.status();
    }
    if (g_interrupted.load() && s.homing_runs()) {
        // The operator gave up: the homing must not go on unattended.
        const Status stop = link.command(device::Command::kStop);
        throw StreamError(link.name() + ": homing interrupted; " +
                          (stop == Status::kOk
                               ? std::string("stop sent")
                               : std::string("stop refused: ") + status_name(stop)));
    }
    show_changes();
    std::string failed;
    for (unsigned a = 0; a < s.axes && a < kMaxAxes; ++a) {
        if ((mask == 0 || (mask & (1u << a)) != 0) &&
            s.homing[a].state == device::AxisHoming::kFailed) {
            failed += (failed.empty() ? "" : "; ") + u.axis_name(a) + ": " +
                      homing_error_name(s.homing[a].error);
        }
    }
    if (o.json) {
        nlohmann::json j;
        j["command"] = "home";
        j["finished"] = !s.homing_runs();
        j["failed"] = !failed.empty();
        j["status"] = to_json(s, u, link.name());
        std::printf("%s\n", j.dump(2).c_str());
    } else {
        std::printf("homing        %s\n", homing_text(s, u).c_str());
        std::printf("position      %s\n", position_text(s, u).c_str());
    }
    if (s.homing_runs()) {
        throw StreamError(link.name() + ": homing did not finish within " + std::to_string(wait) +
                          " s; it goes on (ctl stop ends it)");
    }
    if (!failed.empty()) throw StreamError(link.name() + ": homing failed: " + failed);
    return 0;
}

// pen up|down: the operator's pen at rest (idle only); a jog then carries it.
int run_pen(DeviceLink& link, const CtlCommandOptions& o, const Units& u) {
    if (o.arguments.size() != 1 || (o.arguments[0] != "up" && o.arguments[0] != "down"))
        throw std::invalid_argument("ctl pen: want up or down");
    const bool down = o.arguments[0] == "down";
    const DeviceSnapshot before = link.status();
    const Status r = link.command_with_arguments(device::kCommandPen, 0, down ? 1 : 0, 0);
    if (r != Status::kOk) {
        throw StreamError(link.name() + ": device refused pen " + o.arguments[0] + " while " +
                          device_state_name(before.state) +
                          fault_suffix(before.state, before.fault_code) + ": " + status_name(r));
    }
    DeviceSnapshot s = link.status();
    const auto deadline = Clock::now() + std::chrono::duration<double>(wait_seconds(o, 5));
    while (s.pen_down() != down && Clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        s = link.status();
    }
    if (o.json) {
        std::printf("%s\n", to_json(s, u, link.name()).dump(2).c_str());
    } else {
        std::printf("pen           %s\n", s.pen_down() ? "down" : "up");
    }
    if (s.pen_down() != down)
        throw StreamError(link.name() + ": the device did not " + (down ? "lower" : "raise") +
                          " the pen");
    return 0;
}

}  // namespace

void add_ctl_command(CLI::App& app, CtlCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand("ctl",
                                       "Read a device's status or send it a command, over Modbus "
                                       "TCP/RTU or native CAN (docs/cli.md)");
    cmd->add_option("target", o.target,
                    "device: modbus-tcp://HOST:PORT?unit=N, "
                    "modbus-rtu:///dev/ttyX?baud=115200&parity=N&unit=1 "
                    "or can://IFACE?node=N")
        ->required();
    cmd->add_option(
           "verb", o.verb,
           "status, hold, resume, stop, reset, home [AXES], jog AXIS DISTANCE, pen up|down "
           "or position AXIS VALUE")
        ->required()
        ->check(CLI::IsMember(
            {"status", "hold", "resume", "stop", "reset", "home", "jog", "pen", "position"}));
    cmd->add_option("arguments", o.arguments,
                    "home: axes by name or index (none: every axis the device can home); jog: AXIS "
                    "DISTANCE; position: AXIS VALUE (mm, or LSB with lsb); pen: up or down");
    cmd->add_option("--feed", o.feed, "jog: mm/s (default: the axis's max velocity)")
        ->check(CLI::Range(0.0, 1e6));
    cmd->add_option("--machine,-m", o.machine, "machine profile: positions in mm and axes by name")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--json", o.json,
                  "print one JSON document (with --watch: one JSON object per line)");
    cmd->add_option("--watch", o.watch_seconds,
                    "status: read again every this many seconds until Ctrl-C")
        ->check(CLI::Range(0.01, 3600.0));
    cmd->add_option("--count", o.count,
                    "status --watch: stop after this many reads (0: until Ctrl-C)")
        ->capture_default_str();
    cmd->add_option(
           "--wait", o.wait_seconds,
           "commands: seconds to wait for the state the command leads to (hold: not running; stop, "
           "reset: idle; home: every axis ended; default 5, home 300)")
        ->check(CLI::Range(0.0, 600.0));
    cmd->add_option(
           "--timeout-ms", o.link.response_timeout_ms,
           "Modbus: response timeout per try; native CAN: wait before asking again (at most 100)")
        ->capture_default_str()
        ->check(CLI::Range(10u, 60000u));
    cmd->add_option("--link-timeout", o.link.link_timeout_seconds,
                    "give up after this many seconds without an answer")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 3600.0));
}

int run_ctl(const CtlCommandOptions& o) {
    Units u;
    if (!o.machine.empty()) u.profile = load_machine_profile(o.machine);
    if (o.watch_seconds > 0 && o.verb != "status")
        throw std::invalid_argument("--watch: only with status");
    const std::unique_ptr<DeviceLink> link = open_device_link(o.target, o.link);
    if (u.profile) {
        const DeviceSnapshot s = link->status();
        if (s.axes != u.profile->axes.size()) {
            std::ostringstream m;
            m << link->name() << ": device has " << s.axes << " axes, the profile " << o.machine
              << ' ' << u.profile->axes.size();
            throw StreamError(m.str());
        }
    }
    if (o.verb == "status") return run_status(*link, o, u);
    if (o.verb == "jog") return run_jog(*link, o, u);
    if (o.verb == "position") return run_set_position(*link, o, u);
    if (o.verb == "home") {
        std::signal(SIGINT, on_ctl_signal);
        std::signal(SIGTERM, on_ctl_signal);
        return run_home(*link, o, u);
    }
    if (o.verb == "pen") return run_pen(*link, o, u);
    if (!o.arguments.empty()) throw std::invalid_argument("ctl " + o.verb + ": takes no arguments");
    for (const VerbInfo& v : kVerbs) {
        if (o.verb == v.verb) return run_command(*link, v.command, o, u);
    }
    throw std::invalid_argument("ctl: unknown verb '" + o.verb + "'");
}

}  // namespace pathstream::host
