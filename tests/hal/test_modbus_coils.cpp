// The Modbus client's coil writes (FC5, FC15) against libmodbus's own server (sim::CoilModule,
// a simulated I/O module on loopback): what the module records, the byte counters, a refused
// address, the argument checks, and a module that goes away.
#include <catch2/catch.hpp>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include "pathstream/hal/modbus_adu.hpp"
#include "pathstream/hal/modbus_client.hpp"
#include "pathstream/sim/coil_module.hpp"

using namespace pathstream::hal;
using pathstream::sim::CoilModule;
using Kind = ModbusError::Kind;
using std::chrono::milliseconds;

namespace {

ModbusClientOptions fast(int attempts = 1) {
    ModbusClientOptions o;
    o.response_timeout = milliseconds(300);
    o.byte_timeout = milliseconds(100);
    o.attempts = attempts;
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

TEST_CASE("modbus coils: FC5 and FC15 switch the module's coils", "[modbus][coils][threads]") {
    CoilModule module(16);
    ModbusClient client(module.url(), fast());
    client.write_coil(3, true);
    CHECK(module.coil(3));
    client.write_coil(3, true);  // the same value again: no change
    client.write_coil(3, false);
    CHECK_FALSE(module.coil(3));
    const std::vector<std::uint8_t> values{1, 0, 1, 1};
    client.write_coils(10, values);
    CHECK(module.coil(10));
    CHECK_FALSE(module.coil(11));
    CHECK(module.coil(12));
    CHECK(module.coil(13));
    const std::vector<CoilModule::Change> changes = module.changes();
    REQUIRE(changes.size() == 5);
    CHECK((changes[0].coil == 3 && changes[0].on && changes[0].request == 1));
    CHECK((changes[1].coil == 3 && !changes[1].on && changes[1].request == 3));
    CHECK((changes[2].coil == 10 && changes[2].on && changes[2].request == 4));
    CHECK((changes[4].coil == 13 && changes[4].request == 4));
    CHECK(module.write_requests() == 4);
    // Whole ADUs: FC5 echoes 5 PDU bytes each way; FC15 of 4 coils sends 7 and gets 5 back.
    const ModbusClientCounters& c = client.counters();
    CHECK(c.transactions == 4);
    CHECK(c.adu_bytes_sent == 3 * (7 + 5) + (7 + 7));
    CHECK(c.adu_bytes_received == 3 * (7 + 5) + (7 + 5));
    CHECK(modbus_write_coils_request_pdu_bytes(8) == 7);
    CHECK(modbus_write_coils_request_pdu_bytes(9) == 8);
}

TEST_CASE("modbus coils: a coil the module does not have is refused, nothing changes",
          "[modbus][coils][threads]") {
    CoilModule module(4);
    ModbusClient client(module.url(), fast(3));
    const ModbusError e = error_of([&] { client.write_coil(7, true); });
    CHECK(e.kind() == Kind::kExceptionResponse);
    CHECK(e.exception_code() == 2);
    CHECK(std::string(e.what()).find("FC5 write coil 7 on: exception response 2") !=
          std::string::npos);
    CHECK(client.counters().attempts == 1);  // a definite answer is not retried
    const std::vector<std::uint8_t> values{1, 1};
    CHECK(error_of([&] { client.write_coils(3, values); }).exception_code() == 2);
    CHECK_FALSE(module.coil(3));
    CHECK(module.changes().empty());
}

TEST_CASE("modbus coils: argument checks come before anything is sent",
          "[modbus][coils][threads]") {
    CoilModule module(4);
    ModbusClient client(module.url(), fast());
    CHECK_THROWS_AS(client.write_coils(0, std::vector<std::uint8_t>{}), std::invalid_argument);
    CHECK_THROWS_AS(client.write_coils(0, std::vector<std::uint8_t>(1969, 1)),
                    std::invalid_argument);
    CHECK_THROWS_AS(client.write_coils(65535, std::vector<std::uint8_t>{1, 1}),
                    std::invalid_argument);
    CHECK(client.counters().attempts == 0);
}

TEST_CASE("modbus coils: a module that goes away fails the next write",
          "[modbus][coils][threads]") {
    CoilModule module(4);
    ModbusClient client(module.url(), fast(2));
    client.write_coil(0, true);
    module.stop();
    const ModbusError e = error_of([&] { client.write_coil(0, false); });
    CHECK(e.transient());
    CHECK(std::string(e.what()).find("(after 2 tries)") != std::string::npos);
}
