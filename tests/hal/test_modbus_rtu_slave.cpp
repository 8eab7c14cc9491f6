// The freestanding RTU slave (modbus_rtu_slave.hpp) a firmware image serves with: frames cut
// by the t3.5 silence, CRC and unit checks, every function code answered as the spec says,
// broadcasts executed without an answer, and a real master (libmodbus, through
// hal::ModbusClient) on a pseudo-terminal that cannot tell it from the Linux server.
#include <poll.h>
#include <unistd.h>

#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdint>
#include <thread>
#include <vector>

#include "pathstream/device/wire_span.hpp"
#include "pathstream/hal/modbus_client.hpp"
#include "pathstream/hal/modbus_rtu_slave.hpp"
#include "pathstream/hal/pseudo_terminal.hpp"
#include "register_array.hpp"

using namespace pathstream::hal;
using pathstream::test::RegisterArray;

namespace {

// A request frame: unit, PDU, CRC (low byte first).
std::vector<std::uint8_t> frame_of(std::uint8_t unit, std::vector<std::uint8_t> pdu) {
    std::vector<std::uint8_t> f{unit};
    f.insert(f.end(), pdu.begin(), pdu.end());
    const std::uint16_t crc = pathstream::device::crc16_modbus(f.data(), f.size());
    f.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    f.push_back(static_cast<std::uint8_t>(crc >> 8));
    return f;
}

// The slave's answer to `frame`, CRC checked and stripped; empty when it sent nothing.
std::vector<std::uint8_t> answer(ModbusRtuSlave<RegisterArray>& slave,
                                 const std::vector<std::uint8_t>& frame) {
    std::uint8_t reply[kModbusRtuMaxFrame];
    const std::size_t n = slave.handle(frame.data(), frame.size(), reply);
    if (n == 0) return {};
    REQUIRE(n >= 5);
    const std::uint16_t crc = pathstream::device::crc16_modbus(reply, n - 2);
    REQUIRE(reply[n - 2] == (crc & 0xFF));
    REQUIRE(reply[n - 1] == (crc >> 8));
    return std::vector<std::uint8_t>(reply, reply + n - 2);
}

std::uint32_t micros_now() {
    return static_cast<std::uint32_t>(std::chrono::duration_cast<std::chrono::microseconds>(
                                          std::chrono::steady_clock::now().time_since_epoch())
                                          .count());
}

}  // namespace

TEST_CASE("RTU silent interval: 3.5 characters up to 19200 baud, 1750 us above",
          "[modbus][rtu][slave]") {
    CHECK(modbus_rtu_t35_us(9600) == 4011);
    CHECK(modbus_rtu_t35_us(19200) == 2006);
    CHECK(modbus_rtu_t35_us(19201) == 1750);
    CHECK(modbus_rtu_t35_us(115200) == 1750);
    CHECK(modbus_rtu_t35_us(1000000) == 1750);
}

TEST_CASE("RTU framer: a frame ends at t3.5 of silence, an overlong one is dropped whole",
          "[modbus][rtu][slave]") {
    ModbusRtuFramer f(1750);
    CHECK_FALSE(f.poll(0));
    // Bytes closer than t3.5 are one frame, even across the 32-bit wrap of the clock.
    std::uint32_t t = 0xFFFFF000u;
    for (std::uint8_t b = 1; b <= 8; ++b, t += 1000) f.on_byte(b, t);
    const std::uint32_t last = t - 1000;
    CHECK_FALSE(f.poll(last + 1749));
    REQUIRE(f.poll(last + 1750));
    REQUIRE(f.length() == 8);
    for (std::uint8_t b = 0; b < 8; ++b) CHECK(f.frame()[b] == b + 1);
    CHECK(f.poll(last + 5000));  // stays until taken
    f.take();
    CHECK_FALSE(f.poll(last + 10000));
    // Two frames with a silence between them.
    f.on_byte(0xA, 100);
    REQUIRE(f.poll(2000));
    f.on_byte(0xB, 2001);  // the untaken frame gives way to the new one
    REQUIRE(f.poll(4000));
    CHECK((f.length() == 1 && f.frame()[0] == 0xB));
    f.take();
    // An overlong frame is never ready, and the next one is whole.
    for (std::size_t i = 0; i < kModbusRtuMaxFrame + 10; ++i) f.on_byte(0x55, 10000);
    CHECK_FALSE(f.poll(20000));
    CHECK(f.overflows() == 1);
    f.on_byte(0x01, 30000);
    f.on_byte(0x02, 30001);
    REQUIRE(f.poll(40000));
    CHECK(f.length() == 2);
}

TEST_CASE("RTU framer: a request of known length ends at its last byte when the CRC is right",
          "[modbus][rtu][slave]") {
    ModbusRtuFramer f(1750);
    const std::vector<std::vector<std::uint8_t>> requests = {
        frame_of(7, {0x03, 0x00, 0x09, 0x00, 0x02}),                             // FC3: 8 bytes
        frame_of(7, {0x04, 0x00, 0x02, 0x00, 0x01}),                             // FC4
        frame_of(7, {0x06, 0x00, 0x0A, 0x12, 0x34}),                             // FC6
        frame_of(7, {0x10, 0x00, 0x14, 0x00, 0x02, 4, 0xAB, 0xCD, 0x00, 0x01}),  // FC16: 9 + 4
        frame_of(7, {0x17, 0x00, 0x1E, 0x00, 0x01, 0x00, 0x1E, 0x00, 0x01, 2, 0x00, 0x2A}),
    };
    std::uint32_t t = 0;
    std::uint32_t ended = 0;
    for (const auto& r : requests) {
        // Ready at its last byte, with no silence after it.
        for (std::size_t i = 0; i < r.size(); ++i) {
            CHECK_FALSE(f.poll(t));
            f.on_byte(r[i], t);
            t += 100;
        }
        REQUIRE(f.poll(t - 100));
        CHECK(f.length() == r.size());
        CHECK(std::vector<std::uint8_t>(f.frame(), f.frame() + f.length()) == r);
        f.take();
        CHECK(f.ended_by_length() == ++ended);
        t += 5000;
    }
    // A wrong CRC at the announced length waits for the silence, and the frame is whole there.
    std::vector<std::uint8_t> bad = frame_of(7, {0x03, 0x00, 0x09, 0x00, 0x02});
    bad.back() ^= 0x01;
    for (const std::uint8_t b : bad) f.on_byte(b, t);
    CHECK_FALSE(f.poll(t + 1749));
    REQUIRE(f.poll(t + 1750));
    CHECK(f.length() == 8);
    CHECK(f.ended_by_length() == ended);
    f.take();
    // The silence still ends a request cut short: its first part is a frame of its own.
    const std::vector<std::uint8_t> cut = frame_of(7, {0x03, 0x00, 0x09, 0x00, 0x02});
    t += 10000;
    for (std::size_t i = 0; i < 5; ++i) f.on_byte(cut[i], t);
    REQUIRE(f.poll(t + 1750));
    CHECK(f.length() == 5);
    f.take();
    // A function without a fixed request length ends only at the silence.
    const std::vector<std::uint8_t> other = frame_of(7, {0x2B, 0x0E, 0x01, 0x00});
    t += 10000;
    for (const std::uint8_t b : other) f.on_byte(b, t);
    CHECK_FALSE(f.poll(t + 1000));
    CHECK(f.poll(t + 1750));
    CHECK(f.ended_by_length() == ended);
}

TEST_CASE("RTU slave: every function code answers as the spec says", "[modbus][rtu][slave]") {
    RegisterArray registers;
    ModbusRtuSlave<RegisterArray> slave(registers, 7);
    // FC6 echoes; FC3 reads it back.
    CHECK(answer(slave, frame_of(7, {0x06, 0x00, 0x0A, 0x12, 0x34})) ==
          std::vector<std::uint8_t>{7, 0x06, 0x00, 0x0A, 0x12, 0x34});
    CHECK(registers.holding[10] == 0x1234);
    CHECK(answer(slave, frame_of(7, {0x03, 0x00, 0x09, 0x00, 0x02})) ==
          std::vector<std::uint8_t>{7, 0x03, 4, 0x00, 0x00, 0x12, 0x34});
    // FC4: input register a is 3a + 1.
    CHECK(answer(slave, frame_of(7, {0x04, 0x00, 0x02, 0x00, 0x01})) ==
          std::vector<std::uint8_t>{7, 0x04, 2, 0x00, 7});
    // FC16 answers address and count.
    CHECK(answer(slave, frame_of(7, {0x10, 0x00, 0x14, 0x00, 0x02, 4, 0xAB, 0xCD, 0x00, 0x01})) ==
          std::vector<std::uint8_t>{7, 0x10, 0x00, 0x14, 0x00, 0x02});
    CHECK((registers.holding[20] == 0xABCD && registers.holding[21] == 1));
    // FC23 writes, then reads what it wrote.
    CHECK(answer(slave, frame_of(7, {0x17, 0x00, 0x1E, 0x00, 0x01, 0x00, 0x1E, 0x00, 0x01, 2, 0x00,
                                     0x2A})) == std::vector<std::uint8_t>{7, 0x17, 2, 0x00, 0x2A});
    CHECK(slave.counters().served == 5);
    CHECK(slave.counters().exceptions == 0);
}

TEST_CASE("RTU slave: exceptions, bad frames, other units and broadcasts", "[modbus][rtu][slave]") {
    RegisterArray registers;
    ModbusRtuSlave<RegisterArray> slave(registers, 7);
    // An unknown function, a count out of range, an address beyond the handler's registers,
    // a value the handler refuses.
    CHECK(answer(slave, frame_of(7, {0x2B, 0x0E, 0x01, 0x00})) ==
          std::vector<std::uint8_t>{7, 0xAB, 0x01});
    CHECK(answer(slave, frame_of(7, {0x03, 0x00, 0x00, 0x00, 0x7E})) ==
          std::vector<std::uint8_t>{7, 0x83, 0x03});
    CHECK(answer(slave, frame_of(7, {0x03, 0x03, 0xE7, 0x00, 0x02})) ==
          std::vector<std::uint8_t>{7, 0x83, 0x02});
    CHECK(answer(slave, frame_of(7, {0x06, 0x00, 0x01, 0xDE, 0xAD})) ==
          std::vector<std::uint8_t>{7, 0x86, 0x03});
    CHECK(registers.holding[1] == 0);
    CHECK(slave.counters().exceptions == 4);
    // A wrong CRC, a runt and another unit's request get no answer.
    std::vector<std::uint8_t> bad = frame_of(7, {0x03, 0x00, 0x00, 0x00, 0x01});
    bad.back() ^= 1;
    CHECK(answer(slave, bad).empty());
    CHECK(answer(slave, {7, 0x03, 0x00}).empty());
    CHECK(answer(slave, frame_of(8, {0x06, 0x00, 0x02, 0x00, 0x05})).empty());
    CHECK(registers.holding[2] == 0);
    CHECK(slave.counters().bad_crc == 2);
    CHECK(slave.counters().other_unit == 1);
    // A broadcast write runs without an answer; a broadcast read is not served.
    CHECK(answer(slave, frame_of(0, {0x06, 0x00, 0x03, 0x00, 0x09})).empty());
    CHECK(registers.holding[3] == 9);
    CHECK(answer(slave, frame_of(0, {0x03, 0x00, 0x03, 0x00, 0x01})).empty());
    CHECK(slave.counters().broadcasts == 1);
}

TEST_CASE("RTU slave on a pty: libmodbus as the master cannot tell it from a server",
          "[modbus][rtu][slave][threads]") {
    PseudoTerminal pty(true);
    RegisterArray registers;
    std::atomic<bool> stop{false};
    std::atomic<std::uint32_t> served{0};
    std::atomic<int> short_writes{0};  // Catch's assertions belong to the test's thread
    // The firmware's main loop, on a thread: bytes in with their time, frames out at t3.5.
    std::thread device([&] {
        ModbusRtuSlave<RegisterArray> slave(registers, 5);
        ModbusRtuFramer framer(modbus_rtu_t35_us(115200));
        std::uint8_t reply[kModbusRtuMaxFrame];
        while (!stop.load()) {
            pollfd p{pty.fd(), POLLIN, 0};
            if (::poll(&p, 1, 1) > 0) {
                std::uint8_t in[64];
                const ssize_t n = ::read(pty.fd(), in, sizeof in);
                for (ssize_t i = 0; i < n; ++i) framer.on_byte(in[i], micros_now());
            }
            if (framer.poll(micros_now())) {
                const std::size_t n = slave.handle(framer.frame(), framer.length(), reply);
                framer.take();
                if (n > 0 && ::write(pty.fd(), reply, n) != static_cast<ssize_t>(n))
                    short_writes.fetch_add(1);
                served.store(slave.counters().served);
            }
        }
    });
    {
        ModbusClientOptions o;
        o.response_timeout = std::chrono::milliseconds(500);
        o.attempts = 3;
        ModbusClient master("modbus-rtu://" + pty.peer_path() + "?baud=115200&parity=N&unit=5", o);
        std::vector<std::uint16_t> values(123);
        for (std::size_t i = 0; i < values.size(); ++i)
            values[i] = static_cast<std::uint16_t>(1000 + i);
        master.write_registers(100, values);
        std::vector<std::uint16_t> back(125);
        master.read_holding_registers(100, back);
        for (std::size_t i = 0; i < values.size(); ++i) CHECK(back[i] == values[i]);
        std::vector<std::uint16_t> input(3);
        master.read_input_registers(10, input);
        CHECK((input[0] == 31 && input[1] == 34 && input[2] == 37));
        const std::vector<std::uint16_t> window{7, 8};
        std::vector<std::uint16_t> read(2);
        master.write_read_registers(400, window, 400, read);
        CHECK((read[0] == 7 && read[1] == 8));
        bool refused = false;
        try {
            master.write_register(950, 1);  // read-only in RegisterArray
        } catch (const ModbusError& e) {
            refused = e.exception_code() == 2;
        }
        CHECK(refused);
    }
    stop.store(true);
    device.join();
    CHECK(served.load() >= 5);
    CHECK(short_writes.load() == 0);
}
