// The simulated CiA 402 drive's feed-forward objects: the velocity and torque offsets (0x60B1,
// 0x60B2) over SDO, their sizes, which PDOs may carry them, and bad drive settings refused.
#include <catch2/catch.hpp>
#include <cmath>

#include "cia402_support.hpp"
#include "pathstream/host/cia402_master.hpp"

using namespace pathstream;
using namespace pathstream::host::cia402;
using cia402_test::Rig;

namespace {

// The axes' inertia: 300 per mille of rated torque at the pen plotter's 3000 mm/s^2 (3e6 LSB/s^2).
constexpr double kInertia = 1e-4;

sim::Cia402DriveOptions drive_with_inertia() {
    sim::Cia402DriveOptions d;
    d.torque_per_acceleration = kInertia;
    return d;
}

}  // namespace

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
