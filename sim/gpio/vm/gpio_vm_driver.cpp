// The VM test's driver (docs/gpio.md): a simulated 2-axis plotter (MotionDevice at 1 kHz, real
// time) whose e-stop, limit switches, enable and pen lines are gpio-sim lines opened through
// the libgpiod backend as a machine profile's "gpio" object maps them. Every wait is bounded.
//
//   pathstream_gpio_vm_driver run PROFILE DIR MAX_MS [SWITCH=MM ...]
//       moves (x out to -20 mm and back, then y out to +20 mm and back, again and again) until
//       an e-stop or a limit fault comes: the e-stop from the script (it writes the line's sim
//       pull attribute), a limit switch SWITCH (x-, y+, ...) from the axis itself, which closes
//       it at MM and beyond (sim::MachineSwitches driving the line's gpio-sim pull). DIR/running
//       once enable is up; on e-stop: DIR/estop, waits for the input's release, resets,
//       DIR/reset; on a fault: prints its name, DIR/fault. Then it keeps its lines as they are
//       until DIR/done exists (at most 20 s), so the script can read them. Exit 0 if one came.
//   pathstream_gpio_vm_driver errors CHIP
//       the libgpiod backend's errors on the real chip (unknown line name, offset out of
//       range, a line busy with its holder named).
//   pathstream_gpio_vm_driver measure PROFILE PULL_PATH ROUNDS
//       ROUNDS times: run, write "pull-up" to PULL_PATH (the e-stop line's sim pull) and time
//       the write to the enable line dropping; release, reset, again. Prints the figures.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/homing.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/hal/gpio_gpiod.hpp"
#include "pathstream/linux_device/device_gpio.hpp"
#include "pathstream/linux_device/machine_lines.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/sim/gpio_sim_pull.hpp"
#include "pathstream/sim/machine_switches.hpp"

namespace {

using namespace pathstream;
using Device = device::MotionDevice<2, 64>;
using Glue = linux_device::DeviceGpio<2, 64>;

std::uint64_t now_ns() {
    timespec ts{};
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000u +
           static_cast<std::uint64_t>(ts.tv_nsec);
}

void sleep_until_ns(std::uint64_t t) {
    timespec ts{static_cast<time_t>(t / 1000000000u), static_cast<long>(t % 1000000000u)};
    clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);
}

hal::GpioLineSpec spec(const std::string& chip, const host::GpioLineConfig& c) {
    return linux_device::line_spec(chip, c);
}

// The plotter: device, lines, glue, and a feeder that keeps it moving back and forth.
struct Plotter {
    explicit Plotter(const host::MachineProfile& p) : device(origin()) {
        const host::GpioConfig& g = p.gpio;
        if (!g.present) throw hal::GpioError("the profile has no gpio object");
        if (g.has_estop) estop = hal::open_gpiod_input(spec(g.chip, g.estop), "pathstream-estop");
        if (g.has_enable)
            enable = hal::open_gpiod_output(spec(g.chip, g.enable), "pathstream-enable");
        if (g.has_pen) pen = hal::open_gpiod_output(spec(g.chip, g.pen), "pathstream-pen");
        linux_device::DeviceWiring<2> w;
        w.estop = estop.get();
        w.enable = enable.get();
        w.pen = pen.get();
        for (const auto& [name, line] : g.limits) {
            const unsigned axis = name[0] == 'x' ? 0u : 1u;
            const unsigned side = name[1] == '-' ? 0u : 1u;
            limits.push_back(hal::open_gpiod_input(spec(g.chip, line), "pathstream-limit-" + name));
            w.limit[axis][side] = limits.back().get();
        }
        device::MotionLimits<2> l;
        l.tick_hz = 1000;
        for (auto& a : l.axis) a = {200000, 2000000};
        if (device.configure(l) != Status::kOk) throw hal::GpioError("configure failed");
        glue = std::make_unique<Glue>(device, w);
    }

    static const Lsb (&origin())[2] {
        static const Lsb o[2] = {0, 0};
        return o;
    }

    // Keeps spans queued: x and y in turn, 20 mm out and back, pen down.
    void feed() {
        const device::DeviceState s = device.state();
        if (s == device::DeviceState::kFault || s == device::DeviceState::kEstop ||
            s == device::DeviceState::kStopping)
            return;
        while (device.free_slots() > 8) {
            if (!move.pending()) {
                Lsb from[2] = {end[0], end[1]};
                const unsigned axis = leg % 2;
                const std::int64_t out = axis == 0 ? -20000 : 20000;
                const std::int64_t d = (leg / 2) % 2 == 0 ? out : -out;
                (void)move.plan(from, axis, d, 100000, device.limits());
                end[axis] = static_cast<Lsb>(end[axis] + d);
                ++leg;
            }
            device::WireSpan w;
            if (!move.next(w)) return;
            w.outputs = kOutputPenDown;
            std::uint8_t bytes[4 + 12 * 2];
            const std::size_t n = device::encode_wire_span(w, 2, bytes, sizeof bytes);
            if (device.accept_batch(device.last_accepted_sequence() + 1, 1, bytes, n) !=
                Status::kOk)
                return;
        }
    }

    // After a stop the device rests where it stopped: moves continue from there.
    void restart_moves() {
        end[0] = device.position(0);
        end[1] = device.position(1);
        move = device::AxisMove<2>{};
    }

    // One tick at `deadline`: inputs, tick, outputs, then the switches follow the axes.
    void tick() {
        glue->poll_inputs();
        Lsb out[2];
        device.tick(out);
        glue->update_outputs();
        if (switches.size() != 0) switches.after_tick(out, 2, device.status().position_applied);
        ++ticks;
    }

    // A limit switch of the profile ("x-=-15": closed at -15 mm and below) played by its axis
    // on the line's gpio-sim pull.
    void place_switch(const host::MachineProfile& p, const std::string& arg) {
        const auto eq = arg.find('=');
        const std::string name = arg.substr(0, eq);
        const auto it = std::find_if(p.gpio.limits.begin(), p.gpio.limits.end(),
                                     [&name](const auto& l) { return l.first == name; });
        if (eq == std::string::npos || it == p.gpio.limits.end()) {
            throw hal::GpioError("switch " + arg +
                                 ": want NAME=MM with NAME a limit switch of the profile");
        }
        sim::SwitchPlacement sp;
        sp.axis = name[0] == 'x' ? 0u : 1u;
        sp.side = name.back() == '+' ? device::LimitSide::kPositive : device::LimitSide::kNegative;
        sp.trigger = static_cast<Lsb>(std::llround(std::stod(arg.substr(eq + 1)) / p.mm_per_lsb));
        const hal::GpioLineLocation where = hal::locate_gpiod_line(spec(p.gpio.chip, it->second));
        auto pull = std::make_shared<sim::GpioSimPull>(where.chip_name, where.offset,
                                                       it->second.active_low);
        switches.place(sp, [pull](bool closed) { pull->set(closed); });
        std::printf("driver: switch %s at %s mm played by axis %u on %s\n", name.c_str(),
                    arg.substr(eq + 1).c_str(), sp.axis, pull->path().c_str());
    }

    Device device;
    std::unique_ptr<hal::DigitalInput> estop;
    std::vector<std::unique_ptr<hal::DigitalInput>> limits;
    std::unique_ptr<hal::DigitalOutput> enable, pen;
    std::unique_ptr<Glue> glue;
    device::AxisMove<2> move;
    sim::MachineSwitches switches;
    Lsb end[2] = {0, 0};
    unsigned leg = 0;
    std::uint64_t ticks = 0;
};

void touch(const std::string& path) {
    std::ofstream(path) << "1\n";
}

bool exists(const std::string& path) {
    return std::ifstream(path).good();
}

bool write_attr(const std::string& path, const char* value) {
    std::ofstream out(path);
    out << value;
    out.flush();
    return static_cast<bool>(out);
}

const char* state_name(device::DeviceState s) {
    switch (s) {
        case device::DeviceState::kIdle:
            return "idle";
        case device::DeviceState::kRunning:
            return "running";
        case device::DeviceState::kHolding:
            return "holding";
        case device::DeviceState::kStopping:
            return "stopping";
        case device::DeviceState::kFault:
            return "fault";
        case device::DeviceState::kEstop:
            return "estop";
    }
    return "?";
}

std::string fault_text(device::FaultCode code) {
    char buf[64];
    device::fault_name(code, buf, sizeof buf);
    return buf;
}

// Keeps ticking with the lines as they are until the script has read them (DIR/done), at most
// 20 s: a fixed hold raced the script on a loaded machine.
int hold_until_done(Plotter& p, const std::string& dir, std::uint64_t& deadline) {
    const std::uint64_t period = 1000000;
    for (int i = 0; i < 20000; ++i) {
        deadline += period;
        sleep_until_ns(deadline);
        p.tick();
        if (i % 10 == 0 && exists(dir + "/done")) return 0;
    }
    std::printf("driver: FAIL: %s/done did not appear within 20 s\n", dir.c_str());
    return 1;
}

int run(const host::MachineProfile& profile, const std::string& dir, std::uint64_t max_ms,
        const std::vector<std::string>& switches) {
    Plotter p(profile);
    for (const std::string& sw : switches) p.place_switch(profile, sw);
    p.feed();
    if (p.device.command(device::Command::kStart) != Status::kOk)
        return std::fprintf(stderr, "start refused\n"), 1;
    const std::uint64_t period = 1000000;  // 1 kHz
    std::uint64_t deadline = now_ns();
    device::DeviceState last = p.device.state();
    bool running_marked = false;
    std::uint64_t estop_tick = 0;
    Lsb frozen[2] = {0, 0};
    for (std::uint64_t k = 0; k < max_ms; ++k) {
        deadline += period;
        sleep_until_ns(deadline);
        const std::uint32_t edges_before = p.glue->estop_edges();
        const Lsb before[2] = {p.device.position(0), p.device.position(1)};
        p.tick();
        const std::uint64_t after_ns = now_ns();
        p.feed();
        const device::DeviceState s = p.device.state();
        if (s != last) {
            std::printf("driver: tick %llu: %s -> %s\n", static_cast<unsigned long long>(p.ticks),
                        state_name(last), state_name(s));
            if (s == device::DeviceState::kEstop) {
                estop_tick = p.ticks;
                frozen[0] = p.device.position(0);
                frozen[1] = p.device.position(1);
                const bool same = frozen[0] == before[0] && frozen[1] == before[1];
                const std::uint64_t edge = p.glue->last_estop_edge_ns();
                std::printf(
                    "driver: estop: reaction %s tick (edge seen by the poll before tick %llu, "
                    "state estop "
                    "and enable dropped after it); setpoint repeated: %s; kernel edge timestamp -> "
                    "enable "
                    "dropped: %llu us\n",
                    p.glue->estop_edges() > edges_before ? "1" : "<=1",
                    static_cast<unsigned long long>(p.ticks), same ? "yes" : "NO",
                    static_cast<unsigned long long>(
                        edge != 0 && after_ns > edge ? (after_ns - edge) / 1000 : 0));
                std::fflush(stdout);
                if (!same) return 1;
                touch(dir + "/estop");
            }
            if (s == device::DeviceState::kFault) {
                std::printf("driver: fault: %s\n", fault_text(p.device.fault_code()).c_str());
                std::fflush(stdout);
                touch(dir + "/fault");
                return hold_until_done(p, dir, deadline);
            }
            if (s == device::DeviceState::kIdle && estop_tick != 0) {
                std::printf("driver: reset after e-stop: idle, enable %s\n",
                            device::enable_asserted(s) ? "high" : "low");
                touch(dir + "/reset");
                return hold_until_done(p, dir, deadline);
            }
            last = s;
        }
        if (s == device::DeviceState::kRunning && !running_marked && k > 50) {
            running_marked = true;
            touch(dir + "/running");
        }
        if (s == device::DeviceState::kEstop) {
            if (p.device.position(0) != frozen[0] || p.device.position(1) != frozen[1]) {
                std::printf("driver: FAIL: moved during e-stop\n");
                return 1;
            }
            if (!p.estop->active()) (void)p.device.command(device::Command::kReset);
        }
    }
    std::printf("driver: FAIL: nothing happened within %llu ms\n",
                static_cast<unsigned long long>(max_ms));
    return 1;
}

int measure(const host::MachineProfile& profile, const std::string& pull, int rounds) {
    Plotter p(profile);
    const std::uint64_t period = 1000000;
    std::uint64_t deadline = now_ns();
    std::vector<double> us;
    std::vector<std::uint64_t> tick_counts;
    for (int r = 0; r < rounds; ++r) {
        p.restart_moves();
        p.feed();
        if (p.device.command(device::Command::kStart) != Status::kOk)
            return std::fprintf(stderr, "start refused\n"), 1;
        // Run 100 ticks, then make the edge and time it.
        for (int i = 0; i < 100; ++i) {
            deadline += period;
            sleep_until_ns(deadline);
            p.tick();
            p.feed();
        }
        if (p.device.state() != device::DeviceState::kRunning)
            return std::fprintf(stderr, "not running\n"), 1;
        const std::uint64_t t0 = now_ns();
        const std::uint64_t tick0 = p.ticks;
        if (!write_attr(pull, "pull-up"))
            return std::fprintf(stderr, "cannot write %s\n", pull.c_str()), 1;
        bool dropped = false;
        for (int i = 0; i < 1000 && !dropped; ++i) {
            deadline = std::max(deadline + period, now_ns());  // the write took time: no burst
            sleep_until_ns(deadline);
            p.tick();
            dropped = p.device.state() == device::DeviceState::kEstop;
        }
        const std::uint64_t t1 = now_ns();
        if (!dropped) return std::fprintf(stderr, "no e-stop within 1000 ticks\n"), 1;
        us.push_back(static_cast<double>(t1 - t0) / 1000.0);
        tick_counts.push_back(p.ticks - tick0);
        write_attr(pull, "pull-down");
        for (int i = 0; i < 2000 && p.device.state() != device::DeviceState::kIdle; ++i) {
            deadline += period;
            sleep_until_ns(deadline);
            if (!p.estop->active()) (void)p.device.command(device::Command::kReset);
            p.tick();
        }
        if (p.device.state() != device::DeviceState::kIdle)
            return std::fprintf(stderr, "no reset\n"), 1;
    }
    std::vector<double> sorted = us;
    std::sort(sorted.begin(), sorted.end());
    const std::uint64_t max_ticks = *std::max_element(tick_counts.begin(), tick_counts.end());
    std::printf(
        "driver: measure: %d e-stops, sysfs pull write -> enable line low: min %.0f us, median "
        "%.0f us, "
        "max %.0f us; ticks from the write to the e-stop state: max %llu\n",
        rounds, sorted.front(), sorted[sorted.size() / 2], sorted.back(),
        static_cast<unsigned long long>(max_ticks));
    return 0;
}

// The backend's errors against the real chip: each message must name chip and line.
int errors(const std::string& chip) {
    int failures = 0;
    auto expect = [&](const hal::GpioLineSpec& s, bool output, const std::string& want) {
        std::string got = "no error";
        try {
            if (output) {
                (void)hal::open_gpiod_output(s, "pathstream-errors");
            } else {
                (void)hal::open_gpiod_input(s, "pathstream-errors");
            }
        } catch (const hal::GpioError& e) {
            got = e.what();
        }
        std::printf("driver: error: %s\n", got.c_str());
        if (got.find(want) == std::string::npos) {
            std::printf("driver: FAIL: expected '%s'\n", want.c_str());
            ++failures;
        }
    };
    expect({chip, "no-such-line", false, hal::Bias::kAsIs}, false,
           "gpio " + chip + " line \"no-such-line\": the chip has no line of that name");
    expect({chip, "16", false, hal::Bias::kAsIs}, true,
           "gpio " + chip + " line \"16\": offset out of range (the chip has 16 lines)");
    // A line held by another request: busy, and the holder is named.
    const hal::GpioLineSpec estop{chip, "estop", false, hal::Bias::kAsIs};
    auto held = hal::open_gpiod_input(estop, "pathstream-holder");
    expect(
        estop, false,
        "gpio " + chip + " line \"estop\": request edge events (in use by \"pathstream-holder\")");
    expect(estop, true, "request as output (in use by \"pathstream-holder\")");
    return failures == 0 ? 0 : 1;
}

int usage() {
    std::fprintf(stderr,
                 "usage: pathstream_gpio_vm_driver run PROFILE DIR MAX_MS [SWITCH=MM ...]\n"
                 "       pathstream_gpio_vm_driver measure PROFILE PULL_PATH ROUNDS\n"
                 "       pathstream_gpio_vm_driver errors CHIP\n");
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc == 3 && std::string(argv[1]) == "errors") {
        try {
            return errors(argv[2]);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "pathstream_gpio_vm_driver: %s\n", e.what());
            return 1;
        }
    }
    if (argc < 5) return usage();
    const std::string mode = argv[1];
    try {
        const host::MachineProfile profile = host::load_machine_profile(argv[2]);
        if (mode == "run") {
            return run(profile, argv[3], std::strtoull(argv[4], nullptr, 10),
                       std::vector<std::string>(argv + 5, argv + argc));
        }
        if (argc != 5) return usage();
        if (mode == "measure") return measure(profile, argv[3], std::atoi(argv[4]));
    } catch (const std::exception& e) {
        std::fprintf(stderr, "pathstream_gpio_vm_driver: %s\n", e.what());
        return 1;
    }
    return usage();
}
