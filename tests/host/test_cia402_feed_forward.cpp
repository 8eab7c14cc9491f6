// CiA 402 feed-forward: the velocity and torque offsets (0x60B1, 0x60B2) mapped into RPDO2
// over SDO, sent every cycle from the exact targets, used by the simulated drive, and the
// following error they remove on an example path; the objects' sizes and PDO directions; bad
// settings refused.
#include <catch2/catch.hpp>
#include <cmath>

#include "cia402_support.hpp"
#include "pathstream/host/cia402_master.hpp"

using namespace pathstream;
using namespace pathstream::host::cia402;
using cia402_test::Rig;
using host::Cia402FeedForward;

namespace {

// The axes' inertia: 300 per mille of rated torque at the pen plotter's 3000 mm/s^2 (3e6 LSB/s^2).
constexpr double kInertia = 1e-4;

sim::Cia402DriveOptions drive_with_inertia() {
    sim::Cia402DriveOptions d;
    d.torque_per_acceleration = kInertia;
    return d;
}

host::Cia402Options options(Cia402FeedForward ff) {
    host::Cia402Options o;
    o.nodes = {1, 2};
    o.cycle_ms = 2;
    o.feed_forward = ff;
    o.torque_per_acceleration = ff == Cia402FeedForward::kTorque ? kInertia : 0;
    return o;
}

struct Run {
    host::Cia402Report report;
    double max_following_error = 0;  // LSB, the worse drive
};

Run drive_wave(Cia402FeedForward ff) {
    const cia402_test::Job job = cia402_test::plan_example("wave.json");
    const std::vector<std::int32_t> expected = cia402_test::cycle_setpoints(job.plan, 2, 2);
    Rig rig(2, {expected[0], expected[1]}, 0, 1, drive_with_inertia());
    Run r;
    r.report =
        host::stream_cia402(job.plan, job.machine, options(ff), rig.master_bus, rig.hub.clock);
    for (std::size_t a = 0; a < 2; ++a) {
        const auto& d = *rig.drives[a];
        r.max_following_error = std::max(r.max_following_error, d.max_following_error());
        // The targets are the core's setpoints whatever rides along with them.
        const auto& got = d.applied_targets();
        const std::size_t rows = expected.size() / 2;
        REQUIRE(got.size() >= rows);
        for (std::size_t k = 0; k < rows; ++k) REQUIRE(got[k] == expected[k * 2 + a]);
        CHECK(d.velocity_offset() == 0);  // wound down at the end point
        CHECK(d.torque_offset() == 0);
    }
    return r;
}

}  // namespace

TEST_CASE("feed-forward objects are mapped into RPDO2 over SDO", "[cia402]") {
    for (const auto ff :
         {Cia402FeedForward::kNone, Cia402FeedForward::kVelocity, Cia402FeedForward::kTorque}) {
        INFO("feed-forward " << host::cia402_feed_forward_name(ff));
        Rig rig(2, {}, 0, 1, drive_with_inertia());
        host::Cia402Master m(rig.master_bus, rig.hub.clock, options(ff));
        m.configure();
        for (std::uint8_t n = 1; n <= 2; ++n) {
            if (ff == Cia402FeedForward::kNone) {
                CHECK(m.sdo_upload(n, kRpdo2Communication, 1) == (kPdoInvalid | (0x300u + n)));
                continue;
            }
            CHECK(m.sdo_upload(n, kRpdo2Communication, 1) == 0x300u + n);
            CHECK(m.sdo_upload(n, kRpdo2Communication, 2) == 1u);  // synchronous, as RPDO1
            CHECK(m.sdo_upload(n, kRpdo2Mapping, 1) == 0x60B10020u);
            if (ff == Cia402FeedForward::kTorque) {
                CHECK(m.sdo_upload(n, kRpdo2Mapping, 0) == 2u);
                CHECK(m.sdo_upload(n, kRpdo2Mapping, 2) == 0x60B20010u);
            } else {
                CHECK(m.sdo_upload(n, kRpdo2Mapping, 0) == 1u);
            }
            // RPDO1 unchanged: controlword and target.
            CHECK(m.sdo_upload(n, kRpdo1Mapping, 0) == 2u);
            CHECK(m.sdo_upload(n, kRpdo1Mapping, 2) == 0x607A0020u);
        }
    }
}

TEST_CASE("the offsets sent are the exact differences of the targets", "[cia402]") {
    const cia402_test::Job job = cia402_test::plan_example("wave.json");
    const std::vector<std::int32_t> expected = cia402_test::cycle_setpoints(job.plan, 2, 2);
    Rig rig(2, {expected[0], expected[1]}, 0, 1, drive_with_inertia());
    rig.hub.keep_log = true;
    host::Cia402Master m(rig.master_bus, rig.hub.clock, options(Cia402FeedForward::kTorque));
    m.configure();
    rig.hub.log.clear();
    REQUIRE(m.run(job.plan, job.machine).completed);
    // Node 1's cycles: RPDO1 (target) then RPDO2 (offsets), both before the SYNC.
    std::vector<std::int64_t> t;
    std::vector<std::uint16_t> cw;
    std::vector<std::int32_t> v;
    std::vector<std::int16_t> q;
    for (const auto& f : rig.hub.log) {
        if (f.id == 0x201) {
            cw.push_back(static_cast<std::uint16_t>(f.data[0] | f.data[1] << 8));
            t.push_back(static_cast<std::int32_t>(f.data[2] | f.data[3] << 8 | f.data[4] << 16 |
                                                  f.data[5] << 24));
        }
        if (f.id == 0x301) {
            REQUIRE(f.length == 6);
            REQUIRE(v.size() + 1 == t.size());
            v.push_back(static_cast<std::int32_t>(f.data[0] | f.data[1] << 8 | f.data[2] << 16 |
                                                  f.data[3] << 24));
            q.push_back(static_cast<std::int16_t>(f.data[4] | f.data[5] << 8));
        }
    }
    REQUIRE(t.size() > 500);
    REQUIRE(v.size() == t.size());
    // Enabling, motion and settling (controlword 0x0F, and the enable's held start before):
    // the formulas on the target sequence. Disabling sends zeros.
    std::size_t moving = 0;
    for (std::size_t k = 2; k + 1 < t.size(); ++k) {
        if (cw[k] != kCwEnableOperation) continue;
        INFO("cycle " << k);
        // Velocity: the cycle's own step over 2 ms (an exact integer here); torque: the
        // central second difference, one cycle ahead, times the inertia.
        REQUIRE(v[k] == (t[k] - t[k - 1]) * 500);
        const double a = static_cast<double>(t[k + 1] - t[k] - t[k - 1] + t[k - 2]) / (2 * 4e-6);
        REQUIRE(q[k] == std::llround(a * kInertia));
        moving += v[k] != 0;
    }
    CHECK(moving > 400);
    CHECK(v.back() == 0);
    CHECK(q.back() == 0);
}

TEST_CASE("feed-forward cuts the following error on wave.json at least tenfold", "[cia402]") {
    const Run none = drive_wave(Cia402FeedForward::kNone);
    const Run velocity = drive_wave(Cia402FeedForward::kVelocity);
    const Run torque = drive_wave(Cia402FeedForward::kTorque);
    INFO("max following error, LSB: none " << none.max_following_error << ", velocity "
                                           << velocity.max_following_error << ", torque "
                                           << torque.max_following_error);
    // Without: the 100 Hz loop's lag 2 zeta v / omega, hundreds of LSB at the pen plotter's speeds.
    CHECK(none.max_following_error > 200);
    CHECK(velocity.max_following_error * 10 <= none.max_following_error);
    CHECK(torque.max_following_error <= velocity.max_following_error);
    // The master's own view (target sent vs actual reported) agrees.
    CHECK(velocity.report.max_lag * 10 <= none.report.max_lag);
    CHECK(none.report.completed);
    CHECK(torque.report.completed);
}

TEST_CASE("bad feed-forward settings are refused", "[cia402]") {
    Rig rig(1, {});
    host::Cia402Options o;
    o.feed_forward = Cia402FeedForward::kTorque;
    CHECK_THROWS_WITH(host::Cia402Master(rig.master_bus, rig.hub.clock, o),
                      Catch::Contains("torque feed-forward needs the axes' inertia"));
    o.torque_per_acceleration = -1;
    CHECK_THROWS_WITH(host::Cia402Master(rig.master_bus, rig.hub.clock, o),
                      Catch::Contains("torque per acceleration must be a number >= 0"));
    o.torque_per_acceleration = NAN;
    CHECK_THROWS_AS(host::Cia402Master(rig.master_bus, rig.hub.clock, o), std::invalid_argument);

    const std::string base = "can://vcan0?protocol=cia402";
    CHECK(host::parse_cia402_target(base, 1).options.feed_forward == Cia402FeedForward::kVelocity);
    CHECK(host::parse_cia402_target(base + "&ff=none", 1).options.feed_forward ==
          Cia402FeedForward::kNone);
    const auto t = host::parse_cia402_target(base + "&ff=torque&inertia=2.5e-4", 1);
    CHECK(t.options.feed_forward == Cia402FeedForward::kTorque);
    CHECK(t.options.torque_per_acceleration == 2.5e-4);
    CHECK_THROWS_WITH(host::parse_cia402_target(base + "&ff=acceleration", 1),
                      Catch::Contains("ff 'acceleration' is not none, velocity or torque"));
    CHECK_THROWS_WITH(host::parse_cia402_target(base + "&ff=torque", 1),
                      Catch::Contains("ff=torque needs inertia=X"));
    CHECK_THROWS_WITH(host::parse_cia402_target(base + "&ff=torque&inertia=-1", 1),
                      Catch::Contains("inertia wants a number > 0, not '-1'"));
    CHECK_THROWS_WITH(host::parse_cia402_target(base + "&inertia=lots", 1),
                      Catch::Contains("inertia wants a number > 0"));
}

TEST_CASE("torque feed-forward: a drive without a torque model refuses the mapping", "[cia402]") {
    Rig rig(1, {});  // torque_per_acceleration 0
    host::Cia402Options o;
    o.feed_forward = Cia402FeedForward::kTorque;
    o.torque_per_acceleration = kInertia;
    host::Cia402Master m(rig.master_bus, rig.hub.clock, o);
    CHECK_THROWS_WITH(m.configure(), Catch::Contains("node 1: SDO 0x1601:02 write refused") &&
                                         Catch::Contains("(0x06040041)"));
}

TEST_CASE("torque feed-forward: an inertia beyond INTEGER16 at a_max is refused", "[cia402]") {
    const cia402_test::Job job = cia402_test::plan_example("wave.json");
    Rig rig(2, {}, 0, 1, drive_with_inertia());
    host::Cia402Options o = options(Cia402FeedForward::kTorque);
    o.torque_per_acceleration = 0.02;  // 60000 per mille at 3e6 LSB/s^2
    host::Cia402Master m(rig.master_bus, rig.hub.clock, o);
    CHECK_THROWS_WITH(m.run(job.plan, job.machine),
                      "CiA 402: axis x would need a torque offset of 60000 per mille at a_max, "
                      "beyond 0x60B2's 32767: check the inertia");
}

TEST_CASE("a drive's torque per acceleration must be finite and >= 0", "[cia402]") {
    Rig rig(1, {});
    sim::Cia402DriveOptions d;
    d.torque_per_acceleration = -1e-4;
    CHECK_THROWS_WITH(sim::SimulatedCia402Drive(rig.master_bus, d),
                      Catch::Contains("torque per acceleration must be a finite number >= 0"));
    d.torque_per_acceleration = NAN;
    CHECK_THROWS_AS(sim::SimulatedCia402Drive(rig.master_bus, d), std::invalid_argument);
}

TEST_CASE("the offset objects over SDO: sizes and mapping direction", "[cia402]") {
    Rig rig(1, {}, 0, 1, drive_with_inertia());
    host::Cia402Options o;
    o.nodes = {1};
    host::Cia402Master m(rig.master_bus, rig.hub.clock, o);
    m.configure();
    auto abort_of = [](const std::function<void()>& f) -> std::uint32_t {
        try {
            f();
        } catch (const host::SdoError& e) {
            return e.code();
        }
        return 0;
    };
    m.sdo_download(1, kVelocityOffset, 0, static_cast<std::uint32_t>(-1234), 4);
    CHECK(static_cast<std::int32_t>(m.sdo_upload(1, kVelocityOffset, 0)) == -1234);
    CHECK(rig.drives[0]->velocity_offset() == -1234);
    m.sdo_download(1, kTorqueOffset, 0, 0xFF38, 2);  // -200 per mille
    CHECK(rig.drives[0]->torque_offset() == -200);
    CHECK(abort_of([&] { m.sdo_download(1, kTorqueOffset, 0, 5, 4); }) == kAbortLength);
    CHECK(abort_of([&] { m.sdo_download(1, kVelocityOffset, 0, 5, 2); }) == kAbortLength);
    // Receive-only: not for a TPDO.
    m.nmt(NmtCommand::kEnterPreOperational, 1);
    m.sdo_download(1, kTpdo1Communication, 1, kPdoInvalid | 0x181, 4);
    m.sdo_download(1, kTpdo1Mapping, 0, 0, 1);
    CHECK(abort_of([&] {
              m.sdo_download(1, kTpdo1Mapping, 1, pdo_mapping(kVelocityOffset, 0, 32), 4);
          }) == kAbortNotMappable);
}
