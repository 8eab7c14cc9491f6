// The Modbus transport over RTU on a pseudo-terminal the server creates: round trips, unit
// filtering, broadcast, dead peer, byte counters.
#include <catch2/catch.hpp>
#include <numeric>
#include <vector>

#include "pathstream/hal/modbus_adu.hpp"
#include "pathstream/hal/modbus_client.hpp"
#include "register_array.hpp"

using namespace pathstream::hal;
using pathstream::test::eventually;
using pathstream::test::RegisterArray;
using pathstream::test::ServingThread;
using Kind = ModbusError::Kind;
using std::chrono::milliseconds;

namespace {

std::string url_for(const ModbusServer& server, int unit) {
    return "modbus-rtu://" + server.client_device() +
           "?baud=115200&parity=N&unit=" + std::to_string(unit);
}

ModbusClientOptions fast(int attempts = 1) {
    ModbusClientOptions o;
    o.response_timeout = milliseconds(100);
    o.byte_timeout = milliseconds(50);
    o.attempts = attempts;
    return o;
}

ModbusServerOptions unit(int id) {
    ModbusServerOptions o;
    o.unit = id;
    o.byte_timeout = milliseconds(50);
    return o;
}

template <class Call>
ModbusError error_of(Call call) {
    try {
        call();
    } catch (const ModbusError& e) {
        return e;
    }
    FAIL("no ModbusError thrown");
    return ModbusError(Kind::kBadFrame, "unreachable");
}

}  // namespace

TEST_CASE("RTU: FC3, FC4, FC6, FC16 and FC23 round trips on a pty", "[modbus][rtu][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::rtu_pty(registers, unit(17));
    REQUIRE(server.client_device().rfind("/dev/pts/", 0) == 0);
    ServingThread serving(server);
    ModbusClient client(url_for(server, 17), fast());

    std::vector<std::uint16_t> in(125);
    client.read_input_registers(0, in);
    for (std::size_t i = 0; i < in.size(); ++i) CHECK(in[i] == 3 * i + 1);

    std::vector<std::uint16_t> block(123);
    std::iota(block.begin(), block.end(), std::uint16_t{1});
    client.write_registers(200, block);
    client.write_register(199, 0xABCD);
    std::vector<std::uint16_t> back(124);
    client.read_holding_registers(199, back);
    CHECK(back[0] == 0xABCD);
    CHECK(back[123] == 123);

    const std::vector<std::uint16_t> w = {9, 8, 7};
    std::vector<std::uint16_t> r(5);
    client.write_read_registers(11, w, 10, r);
    CHECK(r == std::vector<std::uint16_t>{0, 9, 8, 7, 0});

    std::vector<std::uint16_t> one(1);
    const ModbusError e = error_of([&] { client.read_holding_registers(1000, one); });
    CHECK(e.kind() == Kind::kExceptionResponse);
    CHECK(e.exception_code() == 2);
    const std::vector<std::uint16_t> refused = {1, RegisterArray::kRefusedValue};
    CHECK(error_of([&] { client.write_registers(10, refused); }).exception_code() == 3);
    client.read_holding_registers(10, r);
    CHECK(r == std::vector<std::uint16_t>{0, 9, 8, 7, 0});  // unchanged by the refused write

    serving.stop();
    CHECK(server.counters().requests == 8);
    CHECK(server.counters().exceptions == 2);
    CHECK(server.counters().bad_frames == 0);
    // RTU ADU = unit + PDU + CRC, counted independently on both sides.
    CHECK(server.counters().adu_bytes_received == client.counters().adu_bytes_sent);
    CHECK(server.counters().adu_bytes_sent == client.counters().adu_bytes_received);
    CHECK(client.counters().adu_bytes_sent ==
          modbus_adu_bytes(ModbusFraming::kRtu, 5) * 3 +            // FC4, FC3, FC3 (exception)
              modbus_adu_bytes(ModbusFraming::kRtu, 6 + 2 * 123) +  // FC16
              modbus_adu_bytes(ModbusFraming::kRtu, 5) +            // FC6
              modbus_adu_bytes(ModbusFraming::kRtu, 10 + 2 * 3) +   // FC23
              modbus_adu_bytes(ModbusFraming::kRtu, 6 + 2 * 2) +    // refused FC16
              modbus_adu_bytes(ModbusFraming::kRtu, 5));            // final FC3
}

TEST_CASE("RTU: requests for another unit id are ignored, as on a shared bus",
          "[modbus][rtu][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::rtu_pty(registers, unit(1));
    ServingThread serving(server);
    ModbusClient stranger(url_for(server, 2), fast(2));
    const ModbusError e = error_of([&] { stranger.write_register(0, 42); });
    CHECK(e.kind() == Kind::kTimeout);
    CHECK(stranger.counters().timeouts == 2);
    CHECK(eventually([&] { return server.counters().ignored == 2; }));

    ModbusClient owner(url_for(server, 1), fast());
    std::vector<std::uint16_t> v(1);
    owner.read_holding_registers(0, v);
    CHECK(v[0] == 0);
    serving.stop();
    CHECK(registers.writes_applied == 0);
    CHECK(server.counters().requests == 1);
}

TEST_CASE("RTU: broadcast writes are applied and never answered", "[modbus][rtu][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::rtu_pty(registers, unit(5));
    ServingThread serving(server);
    ModbusClient everyone(url_for(server, 0), fast());
    const std::vector<std::uint16_t> w = {10, 20, 30};
    everyone.write_registers(40, w);  // returns at once: nothing to wait for
    everyone.write_register(43, 40);
    CHECK(everyone.counters().transactions == 2);
    CHECK(everyone.counters().adu_bytes_received == 0);
    CHECK(everyone.counters().adu_bytes_sent ==
          modbus_adu_bytes(ModbusFraming::kRtu, 6 + 6) + modbus_adu_bytes(ModbusFraming::kRtu, 5));
    std::vector<std::uint16_t> v(4);
    CHECK_THROWS_AS(everyone.read_holding_registers(40, v), std::invalid_argument);
    // A refused broadcast changes nothing and is not answered either.
    const std::vector<std::uint16_t> refused = {RegisterArray::kRefusedValue};
    everyone.write_registers(44, refused);

    REQUIRE(eventually([&] { return server.counters().broadcasts == 3; }));
    CHECK(server.counters().adu_bytes_sent == 0);
    CHECK(server.counters().exceptions == 1);

    ModbusClient one(url_for(server, 5), fast());
    std::vector<std::uint16_t> five(5);
    one.read_holding_registers(40, five);
    CHECK(five == std::vector<std::uint16_t>{10, 20, 30, 40, 0});
}

TEST_CASE("RTU: a server that never answers gives a timeout per try", "[modbus][rtu][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::rtu_pty(registers, unit(1));  // never polled
    ModbusClientOptions options = fast(2);
    options.response_timeout = milliseconds(40);
    ModbusClient client(url_for(server, 1), options);
    std::vector<std::uint16_t> v(1);
    const ModbusError e = error_of([&] { client.read_holding_registers(0, v); });
    CHECK(e.kind() == Kind::kTimeout);
    CHECK(client.counters().timeouts == 2);
    CHECK(client.counters().retries == 1);
    CHECK(client.connected());  // RTU keeps the port open; only the line was flushed
    CHECK(client.counters().reconnects == 0);
}

TEST_CASE("RTU: reconnect() reopens the port", "[modbus][rtu][threads]") {
    RegisterArray registers;
    ModbusServer server = ModbusServer::rtu_pty(registers, unit(1));
    ServingThread serving(server);
    ModbusClient client(url_for(server, 1), fast());
    client.write_register(1, 11);
    client.reconnect();
    std::vector<std::uint16_t> v(1);
    client.read_holding_registers(1, v);
    CHECK(v[0] == 11);
    CHECK(client.counters().reconnects == 1);
    CHECK_THROWS_AS(ModbusClient("modbus-rtu:///dev/nonexistent-tty", fast()), ModbusError);
}
