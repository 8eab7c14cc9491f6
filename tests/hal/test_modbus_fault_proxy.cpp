// RTU over a faulty line (PtyFaultProxy): with 1 % of the bytes corrupted or dropped, every
// transaction still completes through retries and the registers end up exactly as written.
#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <catch2/catch.hpp>
#include <vector>

#include "pathstream/hal/modbus_client.hpp"
#include "pathstream/sim/pty_fault_proxy.hpp"
#include "register_array.hpp"

using namespace pathstream::hal;
using pathstream::sim::PtyFaultOptions;
using pathstream::sim::PtyFaultProxy;
using pathstream::test::RegisterArray;
using pathstream::test::ServingThread;
using std::chrono::milliseconds;

namespace {

// N transactions alternating FC16 and FC23 over 32 registers, mirrored in `expected`. Writes
// go to 0..23; FC23 also reads 24..31 (never written, so always zero): reads must come
// through the faults intact too.
void run_transactions(ModbusClient& client, int n, std::array<std::uint16_t, 32>& expected) {
    std::uint32_t x = 12345;  // LCG: the values, deterministic
    for (int t = 0; t < n; ++t) {
        std::vector<std::uint16_t> values(8);
        for (auto& v : values) {
            x = x * 1103515245u + 12345u;
            v = static_cast<std::uint16_t>(x >> 16);
            if (v == RegisterArray::kRefusedValue) v = 0;
        }
        const auto at = static_cast<std::uint16_t>((t * 5) % 17);  // writes stay below 24
        if (t % 2 == 0) {
            client.write_registers(at, values);
        } else {
            std::vector<std::uint16_t> read(8);
            client.write_read_registers(at, std::span(values).first(4), 24, read);
            values.resize(4);
            REQUIRE(std::equal(read.begin(), read.end(), expected.begin() + 24));
        }
        std::copy(values.begin(), values.end(), expected.begin() + at);
    }
}

void faulty_line_case(const PtyFaultOptions& faults, int transactions) {
    PtyFaultProxy proxy(faults);
    proxy.start();
    RegisterArray registers;
    ModbusSerialLine line;
    line.device = proxy.path_a();  // the server opens a serial device, as on real hardware
    line.baud = 115200;
    line.parity = 'N';
    ModbusServerOptions server_options;
    server_options.unit = 9;
    server_options.byte_timeout = milliseconds(20);
    ModbusServer server = ModbusServer::rtu(registers, line, server_options);
    ServingThread serving(server);

    ModbusClientOptions options;
    options.response_timeout = milliseconds(60);
    options.byte_timeout = milliseconds(20);
    options.attempts = 20;
    ModbusClient client("modbus-rtu://" + proxy.path_b() + "?baud=115200&parity=N&unit=9", options);
    std::array<std::uint16_t, 32> expected{};
    run_transactions(client, transactions, expected);

    std::vector<std::uint16_t> final_state(32);
    client.read_holding_registers(0, final_state);
    serving.stop();
    proxy.stop();
    CHECK(std::equal(final_state.begin(), final_state.end(), expected.begin()));
    CHECK(std::equal(expected.begin(), expected.end(), registers.holding.begin()));
    const ModbusClientCounters& c = client.counters();
    CHECK(c.transactions == static_cast<std::uint64_t>(transactions + 1));
    CHECK(c.retries > 0);  // the faults did hit
    CHECK(c.retries == c.timeouts + c.bad_frames);
    INFO("retries " << c.retries << ", timeouts " << c.timeouts << ", bad frames " << c.bad_frames
                    << ", corrupted " << proxy.counters().corrupted << ", dropped "
                    << proxy.counters().dropped << ", server bad frames "
                    << server.counters().bad_frames);
    CHECK(proxy.counters().overflowed == 0);
}

}  // namespace

TEST_CASE("RTU through a line corrupting 1 % of the bytes", "[modbus][rtu][faults][threads]") {
    PtyFaultOptions faults;
    faults.corrupt_rate = 0.01;
    faults.seed = 20240601;
    faulty_line_case(faults, 60);
}

TEST_CASE("RTU through a line dropping 1 % of the bytes", "[modbus][rtu][faults][threads]") {
    PtyFaultOptions faults;
    faults.drop_rate = 0.01;
    faults.seed = 7;
    faulty_line_case(faults, 40);
}

TEST_CASE("the fault proxy forwards both ways and its faults follow the seed",
          "[modbus][faults][threads]") {
    const auto corrupted_after = [](std::uint64_t seed) {
        PtyFaultOptions faults;
        faults.corrupt_rate = 0.05;
        faults.seed = seed;
        PtyFaultProxy proxy(faults);
        std::vector<std::uint8_t> sent(2000);
        for (std::size_t i = 0; i < sent.size(); ++i) sent[i] = static_cast<std::uint8_t>(i * 7);
        // Write raw bytes into side A's far end through a second opener, read them at B.
        const int a = ::open(proxy.path_a().c_str(), O_RDWR | O_NOCTTY);
        const int b = ::open(proxy.path_b().c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK);
        REQUIRE(a >= 0);
        REQUIRE(b >= 0);
        REQUIRE(::write(a, sent.data(), sent.size()) == static_cast<ssize_t>(sent.size()));
        std::vector<std::uint8_t> got;
        const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(5);
        while (got.size() < sent.size() && std::chrono::steady_clock::now() < end) {
            proxy.poll_once(milliseconds(10));
            std::uint8_t buf[512];
            const ssize_t n = ::read(b, buf, sizeof buf);
            if (n > 0) got.insert(got.end(), buf, buf + n);
        }
        // And back: B -> A without faults in the count check, just delivery.
        const std::uint8_t ping[] = {1, 2, 3};
        REQUIRE(::write(b, ping, 3) == 3);
        proxy.poll_once(milliseconds(100));
        std::uint8_t pong[3] = {};
        CHECK(::read(a, pong, 3) == 3);
        ::close(a);
        ::close(b);
        REQUIRE(got.size() == sent.size());
        std::vector<std::size_t> positions;
        for (std::size_t i = 0; i < sent.size(); ++i) {
            if (got[i] != sent[i]) {
                CHECK(__builtin_popcount(got[i] ^ sent[i]) == 1);  // one bit flipped
                positions.push_back(i);
            }
        }
        CHECK(positions.size() == proxy.counters().corrupted);
        return positions;
    };
    const auto first = corrupted_after(99);
    CHECK(first.size() > 50);  // ~100 expected at 5 %
    CHECK(first.size() < 160);
    CHECK(corrupted_after(99) == first);
    CHECK(corrupted_after(100) != first);
}
