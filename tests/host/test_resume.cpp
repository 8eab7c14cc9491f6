// An interrupted drawing continued: a hold asked for while streaming, a host that dies
// mid-stream, and a fault followed by a reset, each at seeded moments; the drawing's path
// ticks of the interrupted run and of the resumed run together are the uninterrupted plan's,
// tick for tick, pen included (over TCP and RTU). Also `pathstream ctl`'s link: status and commands
// over Modbus TCP and native CAN.
#include <unistd.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include "pathstream/device/can_protocol.hpp"
#include "pathstream/device/device_state.hpp"
#include "pathstream/device/jog.hpp"
#include "pathstream/device/modbus_map.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/job_journal.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/resume_path.hpp"
#include "pathstream/host/svg_path.hpp"
#include "pathstream/linux_device/can_motion_device.hpp"
#include "pathstream/linux_device/modbus_motion_device.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/sim/can_loopback.hpp"
#include "stream_support.hpp"

using namespace pathstream;
using test::Job;
using test::plan_example;
using test::plan_setpoints;
using test::start_of;

namespace {

using device::Command;
using device::DeviceState;

// The simulated Modbus device served over TCP (or RTU on a pty pair) and ticked on its own
// thread.
struct ModbusDeviceThread {
    std::unique_ptr<linux_device::ModbusMotionDevice> device;
    std::unique_ptr<hal::ModbusServer> server;
    std::atomic<bool> stop{false};
    std::thread thread;

    // `limits`: configured before the device thread starts (as a host's configuration would).
    bool rtu = false;

    ModbusDeviceThread(const std::vector<Lsb>& start, double time_scale,
                       const host::DeviceLimitsLsb* limits = nullptr, bool over_rtu = false)
        : rtu(over_rtu) {
        device = linux_device::ModbusMotionDevice::create(start);
        if (limits != nullptr) REQUIRE(device->configure(*limits) == Status::kOk);
        device->record(true);
        device->record_every_tick(true);
        server = std::make_unique<hal::ModbusServer>(
            rtu ? hal::ModbusServer::rtu_pty(device->handler())
                : hal::ModbusServer::tcp(device->handler(), {"127.0.0.1", 0, 4}));
        thread = std::thread([this, time_scale] {
            linux_device::DeviceLoopOptions o;
            o.time_scale = time_scale;
            linux_device::run_device_loop(
                *device, [&](std::chrono::microseconds w) { server->poll_once(w); }, o, stop);
        });
    }
    std::string target() const {
        if (rtu) return "modbus-rtu://" + server->client_device() + "?baud=115200&parity=N&unit=1";
        return "modbus-tcp://127.0.0.1:" + std::to_string(server->port()) + "?unit=1";
    }
    void join() {
        stop = true;
        if (thread.joinable()) thread.join();
    }
    ~ModbusDeviceThread() { join(); }
};

host::StreamOptions options_for(const std::string& target) {
    host::StreamOptions o;
    o.target = target;
    o.lead_seconds = 0.1;
    return o;
}

// Waits until the device is in `state` (polling its status), at most 10 s.
host::DeviceSnapshot wait_for(host::DeviceLink& link, DeviceState state) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    host::DeviceSnapshot s = link.status();
    while (s.state != state && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        s = link.status();
    }
    REQUIRE(std::string(host::device_state_name(s.state)) == host::device_state_name(state));
    return s;
}

// The drawing's path ticks the device executed: the interrupted run's, up to the end of its
// last completed span (`kept` ticks), then the resumed run's without its re-entry spans
// (`reentry_ticks` path ticks at `resumed_from`).
struct Executed {
    std::vector<Lsb> setpoints;
    std::vector<std::uint8_t> pen;
};

Executed drawing_ticks(const linux_device::AnyMotionDevice& d, std::size_t kept,
                       std::size_t resumed_from, std::size_t reentry_ticks) {
    const unsigned axes = d.axes();
    Executed e;
    const auto& s = d.recorded_setpoints();
    const auto& t = d.recorded_ticks();
    for (std::size_t k = 0; k < t.size(); ++k) {
        if (k >= kept && k < resumed_from + reentry_ticks) continue;
        e.setpoints.insert(e.setpoints.end(), s.begin() + static_cast<long>(k * axes),
                           s.begin() + static_cast<long>((k + 1) * axes));
        e.pen.push_back(static_cast<std::uint8_t>(t[k].outputs & kOutputPenDown));
    }
    return e;
}

// The executed ticks are the plan's, tick for tick, pen included (the end point is output by
// the non-path tick that ends the job, so it is not among them).
void check_equals_plan(const Executed& e, const host::Plan& plan) {
    const std::size_t axes = plan.spans.front().control.size();
    const std::vector<Lsb> expected = plan_setpoints(plan, axes);
    REQUIRE(e.pen.size() == plan.total_ticks);
    std::size_t k = 0, pen_down = 0;
    for (const auto& span : plan.spans) {
        for (std::uint32_t i = 0; i < span.ticks; ++i, ++k) {
            INFO("tick " << k);
            for (std::size_t a = 0; a < axes; ++a)
                REQUIRE(e.setpoints[k * axes + a] == expected[k * axes + a]);
            REQUIRE(e.pen[k] == (span.pen_down ? 1 : 0));
            pen_down += span.pen_down ? 1 : 0;
        }
    }
    CHECK(pen_down > 0);
}

// No tick the device output (path, stop, re-entry, rest) steps further than the limit allows
// (one LSB of rounding on top of the exact velocity).
void check_steps_within_limits(const linux_device::AnyMotionDevice& d,
                               const host::MachineProfile& machine) {
    const host::DeviceLimitsLsb l = host::device_limits(machine);
    const auto& s = d.every_tick_setpoints();
    const unsigned axes = d.axes();
    for (unsigned a = 0; a < axes; ++a) {
        const double max_step = static_cast<double>(l.max_velocity[a]) / l.tick_hz + 1.0;
        for (std::size_t k = 1; k < s.size() / axes; ++k) {
            const double step =
                std::abs(static_cast<double>(s[k * axes + a]) - s[(k - 1) * axes + a]);
            INFO("axis " << a << " tick " << k);
            REQUIRE(step <= max_step);
        }
    }
}

std::size_t reentry_ticks(const host::JobSpans& job) {
    std::size_t n = 0;
    for (std::size_t i = 0; i < job.origin.size() && job.origin[i] < 0; ++i)
        n += job.plan.spans[i].ticks;
    return n;
}

// Seeds per scenario: 3 in CI, PATHSTREAM_RESUME_SEEDS=N on demand.
unsigned seeds_to_run() {
    const char* env = std::getenv("PATHSTREAM_RESUME_SEEDS");
    return env != nullptr && std::atoi(env) > 0 ? static_cast<unsigned>(std::atoi(env)) : 3u;
}

// Holds the job at a seeded path tick, then streams the held job on; every drawing tick once.
// The hold is asked in the first half of the drawing so that a slow bus (RTU polls take
// longer) still sees the moment before the drawing ends.
void hold_then_resume(const Job& job, unsigned seed, bool rtu) {
    std::mt19937 rng(seed);
    ModbusDeviceThread dt(start_of(job.plan), 4.0, nullptr, rtu);
    std::atomic<int> interrupt{0};
    host::StreamOptions o = options_for(dt.target());
    o.interrupt.request = &interrupt;
    std::uint32_t job_id = 0;
    std::uint64_t seen_ticks = 0;
    const std::uint64_t at =
        std::uniform_int_distribution<std::uint64_t>(50, job.plan.total_ticks / 2)(rng);
    o.observer = [&](const host::StreamTrace& t) {
        job_id = t.job;
        seen_ticks = t.status.ticks_executed;
        if (seen_ticks >= at) interrupt.store(1);
    };
    const host::StreamReport first = host::stream_modbus(job.plan, job.machine, o);
    INFO("interrupted at path tick " << seen_ticks << " (asked at " << at << ")");
    REQUIRE(first.interrupted == 1);
    CHECK(first.final_status.state == DeviceState::kHolding);
    CHECK((first.final_status.flags & 8u) == 0);  // at rest
    CHECK(first.final_status.outputs == 0);       // pen up
    const host::HeldJob held{job_id, first.final_status.last_accepted};
    host::StreamOptions again = options_for(dt.target());
    again.held = &held;
    const host::StreamReport second = host::stream_modbus(job.plan, job.machine, again);
    CHECK(second.interrupted == 0);
    CHECK(second.job == job_id);
    dt.join();
    check_equals_plan(drawing_ticks(*dt.device, dt.device->recorded_ticks().size(), 0, 0),
                      job.plan);
    check_steps_within_limits(*dt.device, job.machine);
}

}  // namespace

TEST_CASE("resume: a hold at a seeded moment, the held job streamed on: every drawing tick once",
          "[resume][modbus][threads]") {
    const Job job = plan_example("wave.json");
    for (unsigned seed = 1; seed <= seeds_to_run(); ++seed) DYNAMIC_SECTION("seed " << seed) {
            hold_then_resume(job, seed, false);
        }
}

TEST_CASE("resume over RTU: a hold at a seeded moment, the held job streamed on",
          "[resume][rtu][threads]") {
    const Job job = plan_example("wave.json");
    for (unsigned seed = 31; seed < 31 + seeds_to_run(); ++seed) DYNAMIC_SECTION("seed " << seed) {
            hold_then_resume(job, seed, true);
        }
}

TEST_CASE("resume: the host dies at a seeded moment, the job goes on from the device's queue",
          "[resume][modbus][threads]") {
    const Job job = plan_example("wave.json");
    for (unsigned seed = 11; seed < 11 + seeds_to_run(); ++seed) {
        DYNAMIC_SECTION("seed " << seed) {
            std::mt19937 rng(seed);
            ModbusDeviceThread dt(start_of(job.plan), 4.0);
            host::StreamOptions o = options_for(dt.target());
            std::uint32_t job_id = 0;
            const std::uint64_t at =
                std::uniform_int_distribution<std::uint64_t>(50, job.plan.total_ticks / 2)(rng);
            struct HostDied {};
            o.observer = [&](const host::StreamTrace& t) {
                job_id = t.job;
                if (t.status.ticks_executed >= at)
                    throw HostDied{};  // nothing more is sent or said
            };
            REQUIRE_THROWS_AS(host::stream_modbus(job.plan, job.machine, o), HostDied);
            const std::unique_ptr<host::DeviceLink> link = host::open_device_link(dt.target(), {});
            host::DeviceSnapshot s = wait_for(*link, DeviceState::kHolding);
            while ((s.flags & 8u) != 0) s = link->status();  // the underrun's stop comes to rest
            CHECK((s.flags & 2u) != 0);                      // held by underrun
            const host::HeldJob held{job_id, s.last_accepted};
            host::StreamOptions again = options_for(dt.target());
            again.held = &held;
            const host::StreamReport second = host::stream_modbus(job.plan, job.machine, again);
            CHECK(second.interrupted == 0);
            dt.join();
            check_equals_plan(drawing_ticks(*dt.device, dt.device->recorded_ticks().size(), 0, 0),
                              job.plan);
            check_steps_within_limits(*dt.device, job.machine);
        }
    }
}

TEST_CASE("resume: a stop or a fault at a seeded moment, then a re-entry from where it rests",
          "[resume][modbus][threads]") {
    // Also under a jerk limit: the device's stop, the resume's re-entry and approach must then
    // keep the acceleration continuous, or the device refuses the resumed job.
    const double jerk = GENERATE(0.0, 1e5);
    INFO("max_jerk " << jerk);
    Job job = plan_example("wave.json");
    if (jerk > 0) {
        for (auto& a : job.machine.axes) a.max_jerk = jerk;
        job.plan = host::plan_path(host::to_bezier_segments(host::load_json_path(
                                       std::string(PATHSTREAM_SOURCE_DIR) + "/examples/wave.json")),
                                   job.machine);
    }
    const host::JobSpans whole = host::job_from_plan(job.plan);
    const host::DeviceLimitsLsb limits = host::device_limits(job.machine);
    for (unsigned seed = 21; seed < 21 + 2 * seeds_to_run(); ++seed) {
        const bool fault = seed % 2 == 0;
        DYNAMIC_SECTION("seed " << seed << (fault ? " fault" : " stop")) {
            std::mt19937 rng(seed);
            ModbusDeviceThread dt(start_of(job.plan), 4.0);
            std::atomic<int> interrupt{0};
            host::StreamOptions o = options_for(dt.target());
            o.interrupt.request = &interrupt;
            std::uint32_t job_id = 0;
            const std::uint64_t at =
                std::uniform_int_distribution<std::uint64_t>(50, job.plan.total_ticks - 50)(rng);
            o.observer = [&](const host::StreamTrace& t) {
                job_id = t.job;
                if (t.status.ticks_executed < at) return;
                if (fault) {
                    dt.device->raise_fault();
                } else {
                    interrupt.store(2);
                }
            };
            host::DeviceSnapshot s;
            const std::unique_ptr<host::DeviceLink> link = host::open_device_link(dt.target(), {});
            if (fault) {
                REQUIRE_THROWS_AS(host::stream_modbus(job.plan, job.machine, o), host::StreamError);
                wait_for(*link, DeviceState::kFault);
                CHECK(link->command(Command::kReset) == Status::kOk);
                s = wait_for(*link, DeviceState::kIdle);
            } else {
                const host::StreamReport r = host::stream_modbus(job.plan, job.machine, o);
                REQUIRE(r.interrupted >= 1);
                s = r.final_status;
                if (r.interrupted == 1) {
                    // The hold came to rest before the stream's next look sent the stop (a short
                    // hold: the request came near a stop of the plan): stop it now.
                    CHECK(s.state == DeviceState::kHolding);
                    CHECK(link->command(Command::kStop) == Status::kOk);
                    s = wait_for(*link, DeviceState::kIdle);
                }
                CHECK(s.state == DeviceState::kIdle);
            }
            // The interrupted run's drawing ticks end with its last completed span; a fault
            // froze the axes inside the next one, whose ticks the resume draws again.
            const std::size_t done = s.last_completed + 1 - job_id;
            std::size_t kept = 0;
            for (std::size_t i = 0; i < done; ++i) kept += job.plan.spans[i].ticks;
            const std::size_t executed = dt.device->recorded_ticks().size();
            CHECK(executed - kept < (fault ? job.plan.spans[done].ticks : 1u));
            const std::vector<Lsb> rest(s.position, s.position + 2);
            const host::JobSpans resumed = host::resume_from(whole, done, rest, limits);
            const host::StreamReport second =
                host::stream_modbus(resumed.plan, job.machine, options_for(dt.target()));
            CHECK(second.interrupted == 0);
            dt.join();
            check_equals_plan(drawing_ticks(*dt.device, kept, executed, reentry_ticks(resumed)),
                              job.plan);
            check_steps_within_limits(*dt.device, job.machine);
        }
    }
}

TEST_CASE("resume_from: the pen-down approach along the tangent, and errors", "[resume]") {
    const Job job = plan_example("wave.json");
    const host::JobSpans whole = host::job_from_plan(job.plan);
    const host::DeviceLimitsLsb limits = host::device_limits(job.machine);
    REQUIRE(limits.pen_down_ticks > 0);
    std::size_t drawing = 0;
    while (!job.plan.spans[drawing].pen_down || job.plan.spans[drawing].control[0][2] == 0)
        ++drawing;
    const std::vector<Lsb> rest = {start_of(job.plan)[0] - 3000, start_of(job.plan)[1] + 2000};
    const host::JobSpans r = host::resume_from(whole, drawing, rest, limits);
    REQUIRE(r.origin.size() >= 2);
    CHECK((r.origin[0] == -1 && r.origin[1] == -1 &&
           r.origin[2] == static_cast<std::int64_t>(drawing)));
    CHECK_FALSE(r.plan.spans[0].pen_down);
    CHECK(r.plan.spans[1].pen_down);
    CHECK(r.plan.spans[1].ticks >= limits.pen_down_ticks);
    CHECK(r.plan.spans[1].ticks % job.plan.spans[drawing].ticks == 0);
    for (std::size_t a = 0; a < 2; ++a) {
        CHECK(r.plan.spans[0].control[a][0] == rest[a]);
        CHECK(r.plan.spans[1].control[a][1] == job.plan.spans[drawing].control[a][0]);
        // The same velocity at every join: tangent per tick.
        const auto& s0 = r.plan.spans[0];
        const auto& s1 = r.plan.spans[1];
        const auto& d = job.plan.spans[drawing];
        CHECK(static_cast<std::int64_t>(s0.control[a][3]) * s1.ticks ==
              static_cast<std::int64_t>(s1.control[a][2]) * s0.ticks);
        CHECK(static_cast<std::int64_t>(s1.control[a][3]) * d.ticks ==
              static_cast<std::int64_t>(d.control[a][2]) * s1.ticks);
    }
    CHECK(r.plan.spans.size() == 2 + job.plan.spans.size() - drawing);
    // Resuming a resumed job skips its re-entry spans; past the end there is nothing to do.
    const host::JobSpans again = host::resume_from(r, 1, rest, limits);
    CHECK(again.origin[again.origin.size() - (job.plan.spans.size() - drawing)] ==
          static_cast<std::int64_t>(drawing));
    CHECK_THROWS_AS(host::resume_from(whole, job.plan.spans.size(), rest, limits),
                    std::invalid_argument);
}

TEST_CASE("resume_from: a running spindle spins up where the device rests, then re-enters",
          "[resume]") {
    const Job job = plan_example("wave.json");
    host::JobSpans whole = host::job_from_plan(job.plan);
    const host::DeviceLimitsLsb limits = host::device_limits(job.machine);
    std::size_t drawing = 0;
    while (!whole.plan.spans[drawing].pen_down || whole.plan.spans[drawing].control[0][2] == 0)
        ++drawing;
    const std::vector<Lsb> rest = {start_of(job.plan)[0] - 3000, start_of(job.plan)[1] + 2000};
    const std::uint64_t spin_up = 70000;  // more than one span's 65,536 ticks
    const host::JobSpans off = host::resume_from(whole, drawing, rest, limits, spin_up);
    for (host::CoreSpan& s : whole.plan.spans) s.machine = kOutputSpindle | kOutputFlood;
    const host::JobSpans on = host::resume_from(whole, drawing, rest, limits, spin_up);
    // Without the spindle nothing is added; with it, two still spans of 70,000 ticks in all
    // at the rest point carry the target's outputs, then the same re-entry and approach.
    REQUIRE(on.plan.spans.size() == off.plan.spans.size() + 2);
    std::uint64_t still = 0;
    for (std::size_t i = 0; i < 2; ++i) {
        const host::CoreSpan& s = on.plan.spans[i];
        CHECK(on.origin[i] == -1);
        CHECK(s.machine == (kOutputSpindle | kOutputFlood));
        CHECK_FALSE(s.pen_down);
        for (std::size_t a = 0; a < 2; ++a) {
            CHECK((s.control[a][0] == rest[a] && s.control[a][1] == rest[a] &&
                   s.control[a][2] == 0 && s.control[a][3] == 0));
        }
        still += s.ticks;
    }
    CHECK(still == spin_up);
    for (std::size_t i = 2; i < on.plan.spans.size(); ++i) {
        INFO("span " << i);
        CHECK(on.plan.spans[i].machine == (kOutputSpindle | kOutputFlood));
        CHECK(on.plan.spans[i].control == off.plan.spans[i - 2].control);
    }
}

TEST_CASE(
    "resume_from under a jerk limit: the re-entry and the approach keep the acceleration "
    "continuous",
    "[resume][jerk]") {
    // wave.json planned for the pen plotter with 1e5 mm/s^3 on both axes; resumed from spans
    // all along it (inside strokes too, where the acceleration is not 0), from a rest point
    // off the path. The whole resumed job, started at rest, is within the exact jerk rules
    // (check_plan's jerk meter: each span's jerk, every join's acceleration step, rest at both
    // ends); the same resume without the jerk limit is not (the test can fail).
    Job job;
    job.machine = host::load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) +
                                             "/examples/machines/pen_plotter.json");
    for (auto& a : job.machine.axes) a.max_jerk = 1e5;
    const auto segments = host::to_bezier_segments(
        host::load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/wave.json"));
    job.plan = host::plan_path(segments, job.machine);
    const host::JobSpans whole = host::job_from_plan(job.plan);
    const host::DeviceLimitsLsb limits = host::device_limits(job.machine);
    host::DeviceLimitsLsb plain = limits;
    plain.max_jerk.assign(plain.max_jerk.size(), 0);
    REQUIRE(limits.pen_down_ticks > 0);
    const std::vector<Lsb> start = start_of(job.plan);
    int resumed_count = 0, plain_over = 0;
    for (std::size_t first = 1; first < job.plan.spans.size(); first += 5) {
        const std::vector<Lsb> rest = {start[0] - 3000 + static_cast<Lsb>(first), start[1] + 2000};
        INFO("resumed from span " << first << " of " << job.plan.spans.size());
        const host::JobSpans r = host::resume_from(whole, first, rest, limits);
        const std::size_t lead = r.plan.spans.size() - (job.plan.spans.size() - first);
        CHECK(lead >= 3);
        CHECK(lead <= 5);
        for (std::size_t a = 0; a < 2; ++a) CHECK(r.plan.spans[0].control[a][0] == rest[a]);
        if (job.plan.spans[first].pen_down) {
            CHECK(r.plan.spans[lead - 1].pen_down);  // the approach
            CHECK(r.plan.spans[lead - 1].ticks >= limits.pen_down_ticks);
        }
        const host::PlanCheck c = host::check_plan(r.plan, segments, job.machine);
        CHECK(c.jerk_limited);
        CHECK(c.max_jerk_fraction_exact <= 1.0);
        CHECK(c.max_join_acceleration_step_fraction <= 1.0);
        CHECK(c.max_acceleration_fraction_exact <= 1.0);
        CHECK(c.max_velocity_fraction_exact <= 1.0);
        ++resumed_count;
        const host::PlanCheck p = host::check_plan(
            host::resume_from(whole, first, rest, plain).plan, segments, job.machine);
        plain_over +=
            p.max_jerk_fraction_exact > 1.0 || p.max_join_acceleration_step_fraction > 1.0 ? 1 : 0;
    }
    CHECK(resumed_count > 10);
    CHECK(plain_over > 0);
}

TEST_CASE("job spans and journal files: round trip, changed or damaged files refused", "[resume]") {
    const Job job = plan_example("wave.json");
    const host::JobSpans whole = host::job_from_plan(job.plan);
    const std::string dir = std::filesystem::temp_directory_path().string() +
                            "/pathstream_test_resume_" + std::to_string(::getpid());
    std::filesystem::create_directories(dir);
    const std::string spans_path = dir + "/wave.plan";
    const std::string hash = host::write_job_spans(whole, spans_path);
    const host::JobSpans back = host::read_job_spans(spans_path, hash);
    REQUIRE(back.plan.spans.size() == whole.plan.spans.size());
    CHECK(back.plan.total_ticks == job.plan.total_ticks);
    CHECK(back.subpaths == whole.subpaths);
    for (std::size_t i = 0; i < whole.plan.spans.size(); ++i) {
        CHECK(back.plan.spans[i].control == whole.plan.spans[i].control);
        CHECK(back.plan.spans[i].pen_down == whole.plan.spans[i].pen_down);
    }
    CHECK_THROWS_WITH(host::read_job_spans(spans_path, "0000000000000000"),
                      Catch::Contains("changed since the journal was written"));
    {
        std::ofstream bad(dir + "/bad.plan");
        bad << "pathstream job spans 1\naxes 2 spans 2 drawing_spans 2 drawing_ticks 16 subpaths "
               "1\n0 0 0 1 8 1 2\n";
    }
    CHECK_THROWS_WITH(host::read_job_spans(dir + "/bad.plan", ""),
                      Catch::Contains("bad.plan:3:1: bad span line"));
    host::JobJournal j;
    j.target = "modbus-tcp://127.0.0.1:1502";
    j.machine = "m.json";
    j.drawing = "wave.json";
    j.plan_file = spans_path;
    j.plan_hash = hash;
    j.job = 7;
    j.acknowledged = 70;
    j.last_completed = 33;
    j.position = {1, -2};
    j.outcome = "held";
    host::write_journal(j, dir + "/j.json");
    const host::JobJournal r = host::read_journal(dir + "/j.json");
    CHECK((r.target == j.target && r.job == 7 && r.acknowledged == 70 && r.last_completed == 33 &&
           r.position == j.position && r.outcome == "held" && r.plan_hash == hash));
    {
        std::ofstream bad(dir + "/j2.json");
        bad << "{\"format\": \"pathstream job journal 1\", \"target\": 3}";
    }
    CHECK_THROWS_WITH(host::read_journal(dir + "/j2.json"), Catch::Contains("j2.json:1:"));
    // A "format" of another type is not this format: an input error, not a JSON type error
    // (found by fuzz_job_journal).
    CHECK_THROWS_AS(host::parse_journal("{\"format\": 48}", "j3.json"), host::InputError);
    CHECK_THROWS_WITH(host::parse_journal("{\"format\": 48}", "j3.json"),
                      Catch::Contains("not a pathstream job journal"));
    // Bound to its job: an edited job id, or the spans of another job with their own hash, are
    // refused by the journal reader, before any device is asked; progress and target may change.
    const auto edited = [&](const std::string& from, const std::string& to) {
        std::ifstream in(dir + "/j.json");
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const std::size_t at = text.find(from);
        REQUIRE(at != std::string::npos);
        text.replace(at, from.size(), to);
        std::ofstream out(dir + "/j3.json");
        out << text;
        return dir + "/j3.json";
    };
    CHECK_THROWS_WITH(host::read_journal(edited("\"job\": 7", "\"job\": 8")),
                      Catch::Contains("\"binding\" does not match"));
    CHECK_THROWS_WITH(
        host::read_journal(edited("\"plan_hash\": \"" + hash, "\"plan_hash\": \"0000000000000000")),
        Catch::Contains("\"binding\" does not match"));
    CHECK_THROWS_WITH(host::read_journal(edited("\"plan_file\": \"", "\"plan_file\": \"/other")),
                      Catch::Contains("j3.json:"));
    CHECK(host::read_journal(edited("\"last_completed\": 33", "\"last_completed\": 40"))
              .last_completed == 40);
    CHECK(host::read_journal(edited("127.0.0.1:1502", "127.0.0.1:1503")).target ==
          "modbus-tcp://127.0.0.1:1503");
}

TEST_CASE("ctl's link: status and every command over Modbus TCP, refusals by name",
          "[ctl][modbus][threads]") {
    const Job job = plan_example("wave.json");
    const host::DeviceLimitsLsb limits = host::device_limits(job.machine);
    ModbusDeviceThread dt(start_of(job.plan), 1.0, &limits);
    const std::unique_ptr<host::DeviceLink> link = host::open_device_link(dt.target(), {});
    host::DeviceSnapshot s = link->status();
    CHECK((s.magic == 0x5053 && s.version == device::modbus::kProtocolVersion && s.axes == 2 &&
           s.state == DeviceState::kIdle));
    CHECK((s.position[0] == start_of(job.plan)[0] && s.position[1] == start_of(job.plan)[1]));
    CHECK(link->command(Command::kHold) == Status::kWrongState);  // idle: nothing to hold
    CHECK(link->command(Command::kResume) == Status::kWrongState);
    CHECK(link->command(Command::kStop) == Status::kOk);  // idle: drops the queue
    host::DeviceSnapshot after = link->status();          // the next tick applies it
    for (int i = 0; i < 500 && after.epoch == s.epoch; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        after = link->status();
    }
    CHECK(after.epoch == s.epoch + 1);
    CHECK(link->command(Command::kReset) == Status::kOk);  // already in effect
    dt.device->raise_fault();
    s = wait_for(*link, DeviceState::kFault);
    CHECK(s.fault_code == 1);
    CHECK(link->command(Command::kStop) == Status::kWrongState);
    CHECK(link->command(Command::kReset) == Status::kOk);
    s = wait_for(*link, DeviceState::kIdle);
    // A jog and a set position through the link.
    REQUIRE(link->command_with_arguments(device::kCommandJog, 1, -4321, 500) == Status::kOk);
    const std::uint32_t jog_job = s.last_accepted + 1;
    for (int i = 0; i < 5000 && !(s.state == DeviceState::kIdle && s.finished_job == jog_job);
         ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        s = link->status();
    }
    CHECK((s.finished_job == jog_job && s.position[1] == start_of(job.plan)[1] - 4321));
    CHECK(link->command_with_arguments(device::kCommandJog, 5, 1, 0) ==
          Status::kControlValueOutOfRange);
    CHECK(link->command_with_arguments(device::kCommandSetPosition, 0, 77, 0) == Status::kOk);
    dt.join();  // the recorded ticks are the device thread's until it stops
    check_steps_within_limits(*dt.device, job.machine);
}

TEST_CASE("ctl's link over native CAN: status, commands, a hold of a running stream",
          "[ctl][can][threads]") {
    const Job job = plan_example("wave.json");
    sim::CanLoopback loop;
    hal::CanBus& device_bus = loop.add_endpoint();
    hal::CanBus& host_bus = loop.add_endpoint();
    hal::CanBus& ctl_bus = loop.add_endpoint();
    std::unique_ptr<linux_device::CanMotionDevice> device =
        linux_device::CanMotionDevice::create(start_of(job.plan), 5);
    device->record(true);
    std::atomic<bool> stop{false};
    std::thread t([&] {
        linux_device::DeviceLoopOptions o;
        o.time_scale = 4.0;
        linux_device::run_can_device_loop(*device, device_bus, o, stop);
    });
    host::CanStreamOptions c;
    c.node = 5;
    c.ack_timeout_ms = 30;
    c.name = "can://loop?node=5";
    const std::unique_ptr<host::DeviceLink> link = host::open_can_link(ctl_bus, c);
    host::DeviceSnapshot s = link->status();
    CHECK((s.version == device::can::kProtocolVersion && s.axes == 2 &&
           s.state == DeviceState::kIdle));
    CHECK((s.position[0] == start_of(job.plan)[0] && s.position[1] == start_of(job.plan)[1]));
    CHECK(link->command(Command::kHold) == Status::kWrongState);
    CHECK(link->command_with_arguments(device::kCommandSetPosition, 2, 0, 0) ==
          Status::kControlValueOutOfRange);
    // A stream on the host bus; ctl holds it from another endpoint, the stream sees the hold
    // and keeps waiting; ctl resumes it and the stream finishes.
    host::CanStreamReport report;
    std::thread streamer([&] { report = host::stream_can(job.plan, job.machine, host_bus, c); });
    s = wait_for(*link, DeviceState::kRunning);
    CHECK(link->command(Command::kHold) == Status::kOk);
    s = wait_for(*link, DeviceState::kHolding);
    while ((s.flags & pathstream::device::can::kFlagOwnMove) != 0) s = link->status();
    const host::DeviceSnapshot rested = link->status();
    CHECK((rested.position[0] == s.position[0] && rested.position[1] == s.position[1]));
    CHECK(link->command(Command::kResume) == Status::kOk);
    streamer.join();
    CHECK(report.ticks_executed == job.plan.total_ticks);
    stop = true;
    t.join();
    test::check_recorded(job.plan, *device, 0);
}

TEST_CASE("pause: a two-layer drawing holds pen up between its layers, resumed from the host",
          "[resume][pause][threads]") {
    Job job;
    job.machine = host::load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) +
                                             "/examples/machines/pen_plotter.json");
    host::Path path =
        host::load_svg_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/two_pens.svg");
    REQUIRE(path.layers.size() == 2);
    path = host::group_by_layer(path);
    host::pause_between_layers(path);
    job.plan = host::plan_path(host::to_bezier_segments(path), job.machine);
    REQUIRE(job.plan.pauses.size() == 1);
    const host::PlanPause pause = job.plan.pauses.front();
    CHECK(path.subpaths.at(pause.subpath).layer == 1);
    ModbusDeviceThread dt(start_of(job.plan), 4.0);
    host::StreamOptions o = options_for(dt.target());
    std::vector<std::size_t> pauses_seen;
    int paused_reads = 0;
    o.interrupt.on_pause = [&](std::size_t index) { pauses_seen.push_back(index); };
    // The operator presses Enter after the host has seen the pause twenty times.
    o.interrupt.resume_requested = [&] { return ++paused_reads > 20; };
    std::uint64_t held_at_ticks = 0;
    bool pen_down_while_paused = false;
    o.observer = [&](const host::StreamTrace& t) {
        if (!t.status.paused()) return;
        held_at_ticks = t.status.ticks_executed;
        pen_down_while_paused = pen_down_while_paused || t.status.pen_down();
        CHECK(t.status.state == DeviceState::kHolding);
    };
    const host::StreamReport r = host::stream_modbus(job.plan, job.machine, o);
    CHECK(r.interrupted == 0);
    REQUIRE(pauses_seen == std::vector<std::size_t>{0});
    CHECK(paused_reads > 20);
    CHECK(held_at_ticks == pause.tick);
    CHECK_FALSE(pen_down_while_paused);
    dt.join();
    check_equals_plan(drawing_ticks(*dt.device, dt.device->recorded_ticks().size(), 0, 0),
                      job.plan);
    check_steps_within_limits(*dt.device, job.machine);
}

TEST_CASE("a stop from another client while streaming ends the stream as a stop, not a refusal",
          "[resume][modbus][threads]") {
    // `pathstream ctl TARGET stop` during a stream: the device drops the job's queue, the next
    // batch no longer joins it and is refused. The stream reports the stop (interrupted 2,
    // stopped_elsewhere), not "device refused spans ... acceleration limit".
    const Job job = plan_example("wave.json");
    for (unsigned seed = 41; seed < 41 + seeds_to_run(); ++seed) {
        DYNAMIC_SECTION("seed " << seed) {
            std::mt19937 rng(seed);
            ModbusDeviceThread dt(start_of(job.plan), 4.0);
            host::StreamOptions o = options_for(dt.target());
            const std::uint64_t at =
                std::uniform_int_distribution<std::uint64_t>(50, job.plan.total_ticks / 2)(rng);
            bool sent = false;
            o.observer = [&](const host::StreamTrace& t) {
                if (sent || t.status.ticks_executed < at) return;
                const std::unique_ptr<host::DeviceLink> other =
                    host::open_device_link(dt.target(), {});
                REQUIRE(other->command(Command::kStop) == Status::kOk);
                sent = true;
            };
            const host::StreamReport r = host::stream_modbus(job.plan, job.machine, o);
            CHECK(sent);
            CHECK(r.interrupted == 2);
            CHECK(r.stopped_elsewhere);
            CHECK(r.final_status.state == DeviceState::kIdle);
            dt.join();
            check_steps_within_limits(*dt.device, job.machine);
        }
    }
}

TEST_CASE("resume reads a journal and its spans from regular files only", "[resume]") {
    // A journal edited to name /dev/zero as its plan would be read without end.
    CHECK_THROWS_WITH(
        host::read_job_spans("/dev/zero", ""),
        Catch::Contains(
            "/dev/zero: not a regular file: a job's spans are a file that stream writes"));
    CHECK_THROWS_WITH(
        host::read_journal("/dev/null"),
        Catch::Contains("/dev/null: not a regular file: a journal is a file that stream writes"));
}
