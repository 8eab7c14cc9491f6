// The Modbus register map over a device, without a transport: status block, configuration,
// commands and span batches, and that every refused write leaves the device unchanged.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/modbus_register_map.hpp"

using namespace pathstream;
using namespace pathstream::device;
using Ex = modbus::Exception;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 16>;
using Map = ModbusRegisterMap<kAxes, 16>;

std::vector<std::uint16_t> config_block(std::uint32_t hz, std::uint32_t v, std::uint32_t a) {
    std::vector<std::uint16_t> r(modbus::config_registers(kAxes), 0);
    r[0] = static_cast<std::uint16_t>(hz >> 16);
    r[1] = static_cast<std::uint16_t>(hz);
    r[2] = kAxes;
    for (unsigned axis = 0; axis < kAxes; ++axis) {
        r[10 + 4 * axis] = static_cast<std::uint16_t>(v >> 16);
        r[11 + 4 * axis] = static_cast<std::uint16_t>(v);
        r[12 + 4 * axis] = static_cast<std::uint16_t>(a >> 16);
        r[13 + 4 * axis] = static_cast<std::uint16_t>(a);
    }
    return r;
}

std::vector<std::uint16_t> window(std::uint32_t first, const std::vector<WireSpan>& spans,
                                  std::size_t from, std::size_t count) {
    const auto bytes = test::batch_bytes<kAxes>(spans, from, count);
    std::vector<std::uint16_t> r = {
        static_cast<std::uint16_t>(first >> 16), static_cast<std::uint16_t>(first),
        static_cast<std::uint16_t>(count), static_cast<std::uint16_t>(bytes.size()),
        crc16_modbus(bytes.data(), bytes.size())};
    for (std::size_t i = 0; i < bytes.size(); i += 2) {
        const std::uint16_t low = i + 1 < bytes.size() ? bytes[i + 1] : 0;
        r.push_back(static_cast<std::uint16_t>((bytes[i] << 8) | low));
    }
    return r;
}

std::vector<std::uint16_t> status(Map& m) {
    std::vector<std::uint16_t> r(modbus::status::kCount);
    REQUIRE(m.read_input_registers(0, modbus::status::kCount, r.data()) == Ex::kNone);
    return r;
}

}  // namespace

TEST_CASE("status block layout", "[device][modbus]") {
    const Lsb start[kAxes] = {-5, 70000};
    Device d(start);
    Map m(d);
    const auto s = status(m);
    CHECK(s[0] == 0x5053);
    CHECK(s[1] == modbus::kProtocolVersion);
    CHECK(s[2] == 0);  // idle
    CHECK(s[4] == 16);
    CHECK(s[5] == 16);
    CHECK(s[10] == 0xFFFF);
    CHECK(s[11] == 0xFFFB);  // -5, high word first
    CHECK(s[12] == 0x0001);
    CHECK(s[13] == 0x1170);  // 70000
    CHECK(s[modbus::status::kAxes] == kAxes);
    std::uint16_t one = 0;
    CHECK(m.read_input_registers(modbus::status::kCount, 1, &one) == Ex::kIllegalDataAddress);
    std::vector<std::uint16_t> mirror(modbus::status::kCount);
    REQUIRE(m.read_holding_registers(0, modbus::status::kCount, mirror.data()) == Ex::kNone);
    CHECK(mirror == s);
    CHECK(m.write_holding_registers(2, 1, &one) == Ex::kIllegalDataAddress);  // status is read-only
}

TEST_CASE("configuration, commands and batches through registers", "[device][modbus]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    Map m(d);
    const auto spans = test::trapezoid_move<kAxes>(start, 20000, 8);
    auto batch = window(1, spans, 0, 6);

    CHECK(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(batch.size()),
                                    batch.data()) ==
          Ex::kServerDeviceFailure);  // not configured yet
    CHECK(status(m)[modbus::status::kLastRefusal] ==
          static_cast<std::uint16_t>(Status::kNotConfigured));

    auto config = config_block(1000, 200000, 2000000);
    CHECK(m.write_holding_registers(modbus::kConfig, 5, config.data()) ==
          Ex::kIllegalDataAddress);  // partial
    auto bad = config;
    bad[2] = 3;  // wrong axis count
    CHECK(m.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(bad.size()),
                                    bad.data()) == Ex::kIllegalDataValue);
    CHECK_FALSE(d.configured());
    REQUIRE(m.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(config.size()),
                                      config.data()) == Ex::kNone);
    std::vector<std::uint16_t> back(config.size());
    REQUIRE(m.read_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(back.size()),
                                     back.data()) == Ex::kNone);
    // Travel written as zeros (no soft limits) reads back as the whole position range.
    auto expected = config;
    for (unsigned a = 0; a < kAxes; ++a) {
        const std::uint16_t t = modbus::config_travel_register(kAxes, a);
        const auto low = static_cast<std::uint32_t>(-kMaxPositionLsb);
        const auto high = static_cast<std::uint32_t>(kMaxPositionLsb);
        expected[t] = static_cast<std::uint16_t>(low >> 16);
        expected[t + 1] = static_cast<std::uint16_t>(low & 0xFFFFu);
        expected[t + 2] = static_cast<std::uint16_t>(high >> 16);
        expected[t + 3] = static_cast<std::uint16_t>(high & 0xFFFFu);
    }
    CHECK(back == expected);

    auto corrupt = batch;
    corrupt[7] ^= 0x0100;  // one payload bit: the check value no longer matches
    CHECK(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(corrupt.size()),
                                    corrupt.data()) == Ex::kIllegalDataValue);
    CHECK(status(m)[modbus::status::kLastRefusal] == static_cast<std::uint16_t>(Status::kBadBatch));
    auto wrong_sequence = window(7, spans, 0, 6);
    CHECK(m.write_holding_registers(modbus::kSpanWindow,
                                    static_cast<std::uint16_t>(wrong_sequence.size()),
                                    wrong_sequence.data()) == Ex::kIllegalDataValue);
    CHECK(d.queued_spans() == 0);

    // FC23: write the batch and read the status in one transaction.
    std::vector<std::uint16_t> s(modbus::status::kCount);
    REQUIRE(m.write_read_holding_registers(modbus::kSpanWindow,
                                           static_cast<std::uint16_t>(batch.size()), batch.data(),
                                           0, modbus::status::kCount, s.data()) == Ex::kNone);
    CHECK(s[modbus::status::kLastAcceptedSequence + 1] == 6);
    CHECK(s[modbus::status::kFreeSlots] == 10);
    // A retry of the same batch (its reply lost) is acknowledged and not queued twice.
    REQUIRE(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(batch.size()),
                                      batch.data()) == Ex::kNone);
    CHECK(d.queued_spans() == 6);
    CHECK(status(m)[modbus::status::kDuplicates] == 1);

    const std::uint16_t start_command = static_cast<std::uint16_t>(Command::kStart);
    const std::uint16_t resume = static_cast<std::uint16_t>(Command::kResume);
    const std::uint16_t nonsense = 99;
    CHECK(m.write_holding_registers(modbus::kCommand, 1, &nonsense) == Ex::kIllegalDataValue);
    CHECK(m.write_holding_registers(modbus::kCommand, 1, &resume) == Ex::kServerDeviceFailure);
    REQUIRE(m.write_holding_registers(modbus::kCommand, 1, &start_command) == Ex::kNone);
    Lsb out[kAxes];
    d.tick(out);
    CHECK(status(m)[modbus::status::kState] == 1);
    // Configuration is refused while running.
    CHECK(m.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(config.size()),
                                    config.data()) == Ex::kServerDeviceFailure);
    // Queue full answers busy.
    auto more = window(7, spans, 6, 12);
    CHECK(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(more.size()),
                                    more.data()) == Ex::kServerDeviceBusy);
    CHECK(status(m)[modbus::status::kRefusals] >= 5);
}

TEST_CASE("a resend with other bytes under the same sequence is refused", "[device][modbus]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    Map m(d);
    auto config = config_block(1000, 200000, 2000000);
    REQUIRE(m.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(config.size()),
                                      config.data()) == Ex::kNone);
    const auto batch = window(1, test::trapezoid_move<kAxes>(start, 20000, 8), 0, 6);
    const auto other = window(1, test::trapezoid_move<kAxes>(start, 10000, 8), 0, 6);
    REQUIRE(batch != other);
    REQUIRE(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(batch.size()),
                                      batch.data()) == Ex::kNone);
    CHECK(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(other.size()),
                                    other.data()) == Ex::kIllegalDataValue);
    CHECK(status(m)[modbus::status::kLastRefusal] ==
          static_cast<std::uint16_t>(Status::kBadSequence));
    CHECK(status(m)[modbus::status::kDuplicates] == 0);
    CHECK(d.queued_spans() == 6);
    // The true resend is still acknowledged as a duplicate.
    CHECK(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(batch.size()),
                                    batch.data()) == Ex::kNone);
    CHECK(status(m)[modbus::status::kDuplicates] == 1);
    CHECK(d.queued_spans() == 6);
    // The tail of the last batch under its numbers, with other bytes: not a resend either.
    const auto tail = window(4, test::trapezoid_move<kAxes>(start, 10000, 8), 3, 3);
    CHECK(m.write_holding_registers(modbus::kSpanWindow, static_cast<std::uint16_t>(tail.size()),
                                    tail.data()) == Ex::kIllegalDataValue);
    CHECK(status(m)[modbus::status::kLastRefusal] ==
          static_cast<std::uint16_t>(Status::kBadSequence));
    CHECK(status(m)[modbus::status::kDuplicates] == 1);
    CHECK(d.queued_spans() == 6);
}

TEST_CASE("tick rates below the profile's range are refused", "[device][modbus]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    Map m(d);
    auto slow = config_block(kMinTickHz - 1, 200000, 2000000);
    CHECK(m.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(slow.size()),
                                    slow.data()) == Ex::kIllegalDataValue);
    auto five = config_block(5, 200000, 2000000);
    CHECK(m.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(five.size()),
                                    five.data()) == Ex::kIllegalDataValue);
    CHECK_FALSE(d.configured());
    auto lowest = config_block(kMinTickHz, 200000, 2000000);
    CHECK(m.write_holding_registers(modbus::kConfig, static_cast<std::uint16_t>(lowest.size()),
                                    lowest.data()) == Ex::kNone);
    CHECK(d.configured());
}
