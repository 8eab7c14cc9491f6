// The device's Modbus register map: a script of FC3/FC4/FC6/FC16/FC23 requests (shapes as the
// transport admits them) and ticks. A refused write changes no device state; a read changes
// nothing at all.
#include <vector>

#include "device_fingerprint.hpp"
#include "fuzz_support.hpp"
#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/device/wire_span.hpp"

namespace {

using namespace pathstream;
using Map = device::ModbusRegisterMap<2, 16>;
using Ex = device::modbus::Exception;

// An address near what the map serves, or anywhere.
std::uint16_t address(fuzz::Input& in) {
    const std::uint16_t bases[] = {0, device::modbus::kCommand, device::modbus::kConfig,
                                   device::modbus::kSpanWindow};
    const std::uint8_t b = in.byte();
    return b < 192 ? static_cast<std::uint16_t>(bases[b & 3u] + (b >> 2) % 8u) : in.u16();
}

std::vector<std::uint16_t> status_block(Map& m) {
    std::vector<std::uint16_t> r(device::modbus::status::kCount);
    if (m.read_input_registers(0, device::modbus::status::kCount, r.data()) != Ex::kNone)
        fuzz::violated("status read");
    return r;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fuzz::Input in(data, size);
    const Lsb start[2] = {0, 0};
    device::MotionDevice<2, 16> d(start);
    Map m(d);
    if ((in.byte() & 1u) != 0) (void)d.configure(fuzz::fuzz_limits<2>());
    std::vector<std::uint16_t> values(125), out(125);
    while (!in.done()) {
        const std::uint8_t op = in.byte() % 6u;
        const std::uint16_t at = address(in);
        if (op == 4) {  // ticks
            Lsb position[2];
            for (unsigned t = in.byte() % 32u; t > 0; --t) d.tick(position);
            continue;
        }
        const auto before = fuzz::fingerprint(d);
        const auto block_before = status_block(m);
        if (op == 0 || op == 1) {  // FC3 / FC4 (1..125 registers)
            const std::uint16_t count = static_cast<std::uint16_t>(1 + in.byte() % 125u);
            (void)(op == 0 ? m.read_holding_registers(at, count, out.data())
                           : m.read_input_registers(at, count, out.data()));
            if (fuzz::fingerprint(d) != before || status_block(m) != block_before)
                fuzz::violated("a read changed state");
            continue;
        }
        // FC6 / FC16 (1..123 registers) or FC23 (write 1..121, read 1..125).
        std::uint16_t count = static_cast<std::uint16_t>(1 + in.byte() % 123u);
        if (op == 5) count = static_cast<std::uint16_t>(1 + count % 121u);
        for (std::uint16_t i = 0; i < count; ++i) values[i] = in.u16();
        // Half the batches carry a correct check value, so the fuzzer reaches the core.
        if (at == device::modbus::kSpanWindow && count >= device::modbus::kSpanHeaderRegisters &&
            (op & 1u)) {
            std::vector<std::uint8_t> bytes;
            for (std::uint16_t i = device::modbus::kSpanHeaderRegisters; i < count; ++i) {
                bytes.push_back(static_cast<std::uint8_t>(values[i] >> 8));
                bytes.push_back(static_cast<std::uint8_t>(values[i]));
            }
            values[3] = static_cast<std::uint16_t>(bytes.size());
            values[4] = device::crc16_modbus(bytes.data(), bytes.size());
        }
        Ex e;
        if (op == 5) {
            const std::uint16_t read_count = static_cast<std::uint16_t>(1 + in.byte() % 125u);
            e = m.write_read_holding_registers(at, count, values.data(), address(in), read_count,
                                               out.data());
        } else {
            e = m.write_holding_registers(at, count, values.data());
        }
        if (e != Ex::kNone && fuzz::fingerprint(d) != before)
            fuzz::violated("a refused write changed the device");
    }
    return 0;
}
