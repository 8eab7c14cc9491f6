// CiA 402 cyclic synchronous position: the enable sequence, and a planned drawing driven at
// 1 ms and 2 ms cycles: every target the drives took is the core's setpoint for that cycle.
#include <catch2/catch.hpp>
#include <cmath>

#include "cia402_support.hpp"
#include "pathstream/host/cia402_master.hpp"

using namespace pathstream;
using namespace pathstream::host::cia402;
using cia402_test::Rig;

TEST_CASE("enable sequence: shutdown, switch on, enable operation", "[cia402]") {
    Rig rig(1, {500});
    rig.hub.keep_log = true;
    host::Cia402Options o;
    o.nodes = {1};
    host::Cia402Master m(rig.master_bus, rig.hub.clock, o);
    m.configure();
    CHECK(rig.drives[0]->state() == DriveState::kSwitchOnDisabled);
    rig.hub.log.clear();
    REQUIRE(m.enable({500}) == host::Cia402Stop::kNone);
    CHECK(rig.drives[0]->state() == DriveState::kOperationEnabled);
    CHECK((rig.drives[0]->statusword() & 0x6F) == 0x27);
    CHECK((m.drives()[0].statusword & 0x6F) == 0x27);
    // The controlwords on the bus, each once its statusword showed the state before it.
    std::vector<std::uint16_t> cws;
    for (const auto& f : rig.hub.log) {
        if (f.id == 0x201) {
            const auto cw = static_cast<std::uint16_t>(f.data[0] | f.data[1] << 8);
            if (cws.empty() || cws.back() != cw) cws.push_back(cw);
            CHECK((f.data[2] | f.data[3] << 8 | f.data[4] << 16 | f.data[5] << 24) == 500);
        }
    }
    CHECK(cws == std::vector<std::uint16_t>{kCwShutdown, kCwSwitchOn, kCwEnableOperation});
    // Every RPDO is followed by a SYNC, and every SYNC answered by TPDO1 (statusword, position).
    std::size_t syncs = 0, tpdos = 0;
    for (const auto& f : rig.hub.log) {
        syncs += f.id == 0x080 && f.length == 0;
        tpdos += f.id == 0x181 && f.length == 6;
    }
    CHECK(syncs == 3);
    CHECK(tpdos == 3);
    CHECK(rig.drives[0]->position_actual() == 500);
}

namespace {

void drive_wave(std::uint32_t cycle_ms) {
    const cia402_test::Job job = cia402_test::plan_example("wave.json");
    const std::size_t axes = job.machine.axes.size();
    const auto c = static_cast<std::uint32_t>(std::lround(cycle_ms * job.machine.tick_hz / 1000));
    const std::vector<std::int32_t> expected = cia402_test::cycle_setpoints(job.plan, axes, c);
    std::vector<std::int32_t> start(expected.begin(),
                                    expected.begin() + static_cast<std::ptrdiff_t>(axes));
    Rig rig(axes, start);
    host::Cia402Options o;
    o.nodes = {1, 2};
    o.cycle_ms = cycle_ms;
    std::vector<double> progress;
    const host::Cia402Report r =
        host::stream_cia402(job.plan, job.machine, o, rig.master_bus, rig.hub.clock,
                            [&](double f) { progress.push_back(f); });
    REQUIRE(r.completed);
    CHECK(r.message.empty());
    const std::size_t rows = expected.size() / axes;
    CHECK(r.motion_cycles == rows);
    CHECK(r.total_motion_cycles == rows);
    CHECK(r.path_ticks == job.plan.total_ticks);
    CHECK(r.missed_feedback == 0);
    REQUIRE(!progress.empty());
    CHECK(progress.back() == Approx(1.0));
    const double cycle_s = cycle_ms / 1000.0;
    for (std::size_t a = 0; a < axes; ++a) {
        INFO("axis " << a << " cycle " << cycle_ms << " ms");
        const auto& d = *rig.drives[a];
        const std::vector<std::int32_t>& got = d.applied_targets();
        // Motion cycles, then the settle cycles holding the end point.
        REQUIRE(got.size() >= rows);
        for (std::size_t k = 0; k < rows; ++k) {
            INFO("cycle " << k);
            REQUIRE(got[k] == expected[k * axes + a]);
        }
        for (std::size_t k = rows; k < got.size(); ++k)
            REQUIRE(got[k] == expected[(rows - 1) * axes + a]);
        // Never a step larger than v_max x cycle (+1 LSB of rounding), checked independently.
        const double v_lsb = job.machine.axes[a].max_velocity / job.machine.mm_per_lsb;
        std::int64_t worst = 0;
        for (std::size_t k = 1; k < got.size(); ++k)
            worst = std::max<std::int64_t>(worst, std::llabs(std::int64_t{got[k]} - got[k - 1]));
        CHECK(worst <= std::floor(v_lsb * cycle_s) + 1);
        CHECK(worst <= r.max_step);
        // The plant followed within its following error window, and arrived.
        CHECK(d.max_following_error() < 5000);
        CHECK(d.max_following_error() > 0);
        CHECK(std::abs(d.position_actual() - expected[(rows - 1) * axes + a]) <= o.settle_window);
        CHECK(d.state() == DriveState::kReadyToSwitchOn);  // disabled at the end
        CHECK(d.stale_syncs() == 0);
        CHECK(r.final_target[a] == expected[(rows - 1) * axes + a]);
    }
}

}  // namespace

TEST_CASE("wave.json in CSP at a 1 ms cycle: targets are the core's setpoints", "[cia402]") {
    drive_wave(1);
}
TEST_CASE("wave.json in CSP at a 2 ms cycle: every second setpoint", "[cia402]") {
    drive_wave(2);
}
