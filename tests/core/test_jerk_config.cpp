// The jerk limit travels like the other limits: appended to the Modbus configuration block and
// as optional CAN configuration items, and reaches the device's checks either way.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "pathstream/device/can_node.hpp"
#include "pathstream/device/modbus_register_map.hpp"

using namespace pathstream;
using namespace pathstream::device;
namespace pc = device::can;

namespace {

constexpr unsigned kAxes = 2;

void put_u32(std::vector<std::uint16_t>& r, std::size_t at, std::uint32_t v) {
    r[at] = static_cast<std::uint16_t>(v >> 16);
    r[at + 1] = static_cast<std::uint16_t>(v & 0xFFFFu);
}

std::vector<std::uint16_t> config_block(const std::uint32_t (&jerk)[kAxes]) {
    std::vector<std::uint16_t> r(modbus::config_registers(kAxes), 0);
    put_u32(r, 0, 1000);
    r[2] = kAxes;
    for (unsigned a = 0; a < kAxes; ++a) {
        put_u32(r, modbus::kConfigAxisBase + 4 * a, 200000);
        put_u32(r, modbus::kConfigAxisBase + 4 * a + 2, 2000000);
        put_u32(r, modbus::config_jerk_register(kAxes, a), jerk[a]);
    }
    return r;
}

}  // namespace

TEST_CASE("Modbus: the jerk limits are appended to the configuration block",
          "[device][jerk][modbus]") {
    // Existing addresses stay: travel of axis 1 at +10 + 8 + 4, the jerk after all travel.
    CHECK(modbus::config_travel_register(kAxes, 1) == 22);
    CHECK(modbus::config_jerk_register(kAxes, 0) == 26);
    CHECK(modbus::config_jerk_register(kAxes, 1) == 28);
    CHECK(modbus::config_registers(kAxes) == 30);
    CHECK(modbus::kConfig + modbus::config_registers(8) == modbus::kSpanWindow);

    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> dev(start);
    ModbusRegisterMap<kAxes, 16> map(dev);
    const std::uint32_t jerk[kAxes] = {0xFFFFFFFFu, 937500};
    const std::vector<std::uint16_t> r = config_block(jerk);
    REQUIRE(map.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(r.size()),
                                        r.data()) == modbus::Exception::kNone);
    CHECK(dev.limits().axis[0].max_jerk == 0xFFFFFFFFu);
    CHECK(dev.limits().axis[1].max_jerk == 937500);
    std::vector<std::uint16_t> back(r.size(), 0xAAAA);
    REQUIRE(map.read_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(back.size()),
                                       back.data()) == modbus::Exception::kNone);
    // (Travel 0, 0 reads back as the whole position range it means.)
    for (unsigned a = 0; a < kAxes; ++a) {
        const std::uint16_t j = modbus::config_jerk_register(kAxes, a);
        CHECK(back[j] == r[j]);
        CHECK(back[j + 1] == r[j + 1]);
    }

    // Zeros there (what a profile without max_jerk writes): no jerk limit.
    const std::uint32_t none[kAxes] = {0, 0};
    const std::vector<std::uint16_t> zero = config_block(none);
    REQUIRE(map.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(zero.size()),
                                        zero.data()) == modbus::Exception::kNone);
    CHECK(dev.limits().axis[0].max_jerk == 0);
    CHECK(dev.limits().axis[1].max_jerk == 0);
    // The old, shorter block is a partial write now.
    CHECK(map.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(zero.size() - 4),
                                      zero.data()) == modbus::Exception::kIllegalDataAddress);
}

TEST_CASE("CAN: jerk items configure the jerk limit, and are optional", "[device][jerk][can]") {
    const Lsb start[kAxes] = {0, 0};
    MotionDevice<kAxes, 16> dev(start);
    pc::CanNode<kAxes, 16> node{dev, 5};
    std::vector<pc::Frame> out;
    auto feed = [&](const pc::Frame& f) {
        node.handle(f, [&](const pc::Frame& o) { out.push_back(o); });
    };
    auto configure = [&](bool with_jerk) {
        feed(pc::encode_config(5, 0, kAxes, 1000));
        for (unsigned a = 0; a < kAxes; ++a) {
            feed(pc::encode_config(5, pc::config_item_velocity(a), kAxes, 200000));
            feed(pc::encode_config(5, pc::config_item_acceleration(a), kAxes, 2000000));
            if (with_jerk) feed(pc::encode_config(5, pc::config_item_jerk(a), kAxes, 1000u + a));
        }
        feed(pc::encode_config(5, pc::kConfigItemPenDown, kAxes, 0));
        pc::Ack ack;
        REQUIRE(pc::decode_ack(out.back(), ack));
        return ack.result;
    };
    CHECK(pc::config_item_jerk(0) == 34);
    CHECK(pc::config_item_jerk(7) == 41);
    REQUIRE(configure(true) == 0);
    CHECK(dev.limits().axis[0].max_jerk == 1000);
    CHECK(dev.limits().axis[1].max_jerk == 1001);
    // A new set without jerk items: no jerk limit.
    REQUIRE(configure(false) == 0);
    CHECK(dev.limits().axis[0].max_jerk == 0);
    CHECK(dev.limits().axis[1].max_jerk == 0);
    // A jerk item for an axis the device does not have is a bad frame.
    feed(pc::encode_config(5, pc::config_item_jerk(kAxes), kAxes, 5));
    pc::Ack ack;
    REQUIRE(pc::decode_ack(out.back(), ack));
    CHECK(ack.result == pc::kResultBadFrame);
}
