// CiA 402 master <-> simulated drive: the protocol tables, target URLs, the SDO configuration
// round trip and the SDO abort codes, decoded into messages.
#include <catch2/catch.hpp>

#include "cia402_support.hpp"
#include "pathstream/host/cia402_master.hpp"

using namespace pathstream;
using namespace pathstream::host::cia402;
using cia402_test::Rig;

TEST_CASE("statusword table and texts", "[cia402]") {
    // The statusword mask/value table of docs/cia402.md (CiA 402's power state machine), with
    // the other bits set or clear: the decoder must look only at the masked bits.
    CHECK(decode_statusword(0x0040) == DriveState::kSwitchOnDisabled);
    CHECK(decode_statusword(0x0250) == DriveState::kSwitchOnDisabled);
    CHECK(decode_statusword(0x0021) == DriveState::kReadyToSwitchOn);
    CHECK(decode_statusword(0x0231) == DriveState::kReadyToSwitchOn);
    CHECK(decode_statusword(0x0023) == DriveState::kSwitchedOn);
    CHECK(decode_statusword(0x0027) == DriveState::kOperationEnabled);
    CHECK(decode_statusword(0x1237) == DriveState::kOperationEnabled);
    CHECK(decode_statusword(0x0007) == DriveState::kQuickStopActive);
    CHECK(decode_statusword(0x0008) == DriveState::kFault);
    CHECK(decode_statusword(0x0218) == DriveState::kFault);
    CHECK(decode_statusword(0x000F) == DriveState::kFaultReactionActive);
    CHECK(decode_statusword(0x0000) == DriveState::kNotReadyToSwitchOn);
    for (auto s :
         {DriveState::kSwitchOnDisabled, DriveState::kReadyToSwitchOn, DriveState::kSwitchedOn,
          DriveState::kOperationEnabled, DriveState::kQuickStopActive, DriveState::kFault,
          DriveState::kFaultReactionActive, DriveState::kNotReadyToSwitchOn}) {
        CHECK(decode_statusword(statusword_bits(s)) == s);
    }
    CHECK(sdo_abort_text(0x06020000) ==
          "object does not exist in the object dictionary (0x06020000)");
    CHECK(sdo_abort_text(0x12345678).find("unknown abort code (0x12345678)") != std::string::npos);
    CHECK(emcy_text(0x8611) == "following error too large (0x8611)");
    CHECK(emcy_text(0x4310) == "temperature (0x4310)");
}

TEST_CASE("cia402 target URLs", "[cia402]") {
    const auto t = host::parse_cia402_target("can://vcan0?node=3&protocol=cia402&cycle=2ms", 2);
    CHECK(t.interface == "vcan0");
    CHECK(t.options.nodes == std::vector<std::uint8_t>{3, 4});
    CHECK(t.options.cycle_ms == 2);
    const auto u = host::parse_cia402_target(
        "can://can1?protocol=cia402&nodes=5,9&cycle=1&heartbeat=50ms&echo=1", 2);
    CHECK(u.options.nodes == std::vector<std::uint8_t>{5, 9});
    CHECK(u.options.cycle_ms == 1);
    CHECK(u.options.heartbeat_ms == 50);
    CHECK(u.options.demand_echo);
    CHECK_THROWS_WITH(host::parse_cia402_target("can://vcan0?node=1", 1),
                      Catch::Contains("protocol=cia402 missing"));
    CHECK_THROWS_WITH(host::parse_cia402_target("can://vcan0?node=0&protocol=cia402", 1),
                      Catch::Contains("outside 1..127"));
    CHECK_THROWS_WITH(host::parse_cia402_target("can://vcan0?nodes=1&protocol=cia402", 2),
                      Catch::Contains("1 nodes for 2 axes"));
    CHECK_THROWS_WITH(host::parse_cia402_target("can://vcan0?protocol=cia402&cycle=fast", 1),
                      Catch::Contains("cycle wants a number"));
    CHECK_THROWS_WITH(host::parse_cia402_target("can://vcan0?protocol=cia402&speed=1", 1),
                      Catch::Contains("unknown key 'speed'"));
}

TEST_CASE("SDO configuration round trip", "[cia402]") {
    Rig rig(2, {100, -200});
    host::Cia402Options o;
    o.nodes = {1, 2};
    o.cycle_ms = 2;
    o.demand_echo = true;
    host::Cia402Master m(rig.master_bus, rig.hub.clock, o);
    m.configure();
    for (std::uint8_t n = 1; n <= 2; ++n) {
        const auto& d = *rig.drives[n - 1];
        INFO("node " << int(n));
        CHECK(d.nmt_state() == NmtState::kOperational);
        CHECK(d.mode() == kModeCsp);
        CHECK(d.interpolation_period_ms() == 2);
        // What the master wrote, read back raw.
        CHECK(m.sdo_upload(n, kRpdo1Communication, 1) == 0x200u + n);
        CHECK(m.sdo_upload(n, kRpdo1Communication, 2) == 1u);
        CHECK(m.sdo_upload(n, kRpdo1Mapping, 0) == 2u);
        CHECK(m.sdo_upload(n, kRpdo1Mapping, 1) == 0x60400010u);
        CHECK(m.sdo_upload(n, kRpdo1Mapping, 2) == 0x607A0020u);
        CHECK(m.sdo_upload(n, kTpdo1Communication, 1) == 0x180u + n);
        CHECK(m.sdo_upload(n, kTpdo1Communication, 2) == 1u);
        CHECK(m.sdo_upload(n, kTpdo1Mapping, 1) == 0x60410010u);
        CHECK(m.sdo_upload(n, kTpdo1Mapping, 2) == 0x60640020u);
        CHECK(m.sdo_upload(n, kTpdo2Communication, 1) == 0x280u + n);
        CHECK(m.sdo_upload(n, kTpdo2Mapping, 1) == 0x60620020u);
        CHECK(m.sdo_upload(n, kHeartbeatProducer, 0) == 100u);
        std::uint8_t size = 0;
        CHECK(m.sdo_upload(n, kInterpolationPeriod, 2, &size) == 0xFDu);  // -3: milliseconds
        CHECK(size == 1);
        CHECK(static_cast<std::int32_t>(m.sdo_upload(n, kPositionActual, 0, &size)) ==
              (n == 1 ? 100 : -200));
        CHECK(size == 4);
        CHECK((m.sdo_upload(n, kDeviceType, 0) & 0xFFFF) == 402u);
    }
    // Every drive heard, and the master knows it is operational.
    for (const auto& v : m.drives()) {
        CHECK(v.heartbeat_seen);
        CHECK(v.nmt == NmtState::kOperational);
    }
}

namespace {

std::uint32_t abort_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const host::SdoError& e) {
        return e.code();
    }
    return 0;
}

}  // namespace

TEST_CASE("SDO aborts are decoded and name node and object", "[cia402]") {
    Rig rig(1, {});
    host::Cia402Options o;
    o.nodes = {1};
    host::Cia402Master m(rig.master_bus, rig.hub.clock, o);
    m.configure();  // NMT operational now

    CHECK_THROWS_WITH(m.sdo_upload(1, 0x2000, 0),
                      "node 1: SDO 0x2000:00 read refused: object does not exist in the object "
                      "dictionary (0x06020000)");
    CHECK(abort_of([&] { m.sdo_upload(1, kInterpolationPeriod, 3); }) == kAbortNoSubindex);
    CHECK(abort_of([&] { m.sdo_download(1, kModesOfOperation, 0, 8, 2); }) == kAbortLength);
    CHECK(abort_of([&] { m.sdo_download(1, kStatusword, 0, 0, 2); }) == kAbortReadOnly);
    CHECK(abort_of([&] { m.sdo_download(1, kModesOfOperation, 0, 3, 1); }) ==
          kAbortValueRange);  // profile velocity: not here
    // Mapping changes in NMT operational: the wrong state.
    CHECK_THROWS_WITH(m.sdo_download(1, kRpdo1Mapping, 0, 0, 1),
                      Catch::Contains("node 1: SDO 0x1600:00 write refused") &&
                          Catch::Contains("because of the present device state (0x08000022)"));
    // In pre-operational with the PDO disabled it works, but not with an unmappable object
    // or more than 64 bits.
    m.nmt(NmtCommand::kEnterPreOperational, 1);
    m.sdo_download(1, kRpdo1Communication, 1, kPdoInvalid | 0x201, 4);
    m.sdo_download(1, kRpdo1Mapping, 0, 0, 1);
    CHECK(abort_of([&] {
              m.sdo_download(1, kRpdo1Mapping, 1, pdo_mapping(kStatusword, 0, 16), 4);
          }) == kAbortNotMappable);
    for (std::uint8_t s = 1; s <= 3; ++s)
        m.sdo_download(1, kRpdo1Mapping, s, pdo_mapping(kTargetPosition, 0, 32), 4);
    CHECK(abort_of([&] { m.sdo_download(1, kRpdo1Mapping, 0, 3, 1); }) == kAbortPdoLength);
    // A node that is not there: retried, then a timeout naming it.
    CHECK_THROWS_WITH(m.sdo_upload(9, kDeviceType, 0),
                      Catch::Contains("no response in 3 tries of 50 ms"));
}

TEST_CASE("configure names a missing drive", "[cia402]") {
    Rig rig(1, {});
    host::Cia402Options o;
    o.nodes = {1, 5};
    host::Cia402Master m(rig.master_bus, rig.hub.clock, o);
    CHECK_THROWS_WITH(m.configure(), Catch::Contains("node 5: no boot-up message within 1000 ms"));
}
