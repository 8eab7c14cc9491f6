// The firmware's Modbus RTU slave: bytes from the line, with silences between them, cut into
// frames at t3.5 and served by the device's register map. Every answer is a well-formed RTU
// frame from our unit (its CRC right, an exception five bytes, a read as long as its byte
// count says); a frame with a wrong CRC, for another unit or broadcast gets none, and one with
// a wrong CRC changes nothing on the device.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "device_fingerprint.hpp"
#include "fuzz_support.hpp"
#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/hal/modbus_rtu_slave.hpp"

namespace {

using namespace pathstream;
using Map = device::ModbusRegisterMap<2, 16>;
constexpr std::uint8_t kUnit = 5;
constexpr std::uint32_t kT35 = 1750;

std::uint16_t crc_of(const std::uint8_t* p, std::size_t n) {
    return device::crc16_modbus(p, n);
}

// What a well-formed answer to `request` looks like.
void check_answer(const std::vector<std::uint8_t>& request, const std::uint8_t* r, std::size_t n) {
    if (n < 5 || n > hal::kModbusRtuMaxFrame) fuzz::violated("answer length");
    if (crc_of(r, n - 2) != static_cast<std::uint16_t>(r[n - 2] | (r[n - 1] << 8)))
        fuzz::violated("answer CRC");
    if (r[0] != kUnit) fuzz::violated("answer unit");
    if ((r[1] & 0x7Fu) != (request[1] & 0x7Fu)) fuzz::violated("answer function");
    if ((r[1] & 0x80u) != 0) {
        if (n != 5) fuzz::violated("exception length");
        const std::uint8_t code = r[2];
        if (code != 1 && code != 2 && code != 3 && code != 4 && code != 6)
            fuzz::violated("exception code");
        return;
    }
    switch (r[1]) {
        case 0x03:
        case 0x04:
        case 0x17:
            if (n != 5u + r[2] || r[2] == 0 || r[2] % 2 != 0) fuzz::violated("read length");
            break;
        case 0x06:
        case 0x10:
            if (n != 8) fuzz::violated("write answer length");
            break;
        default:
            fuzz::violated("answered an unknown function");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fuzz::Input in(data, size);
    const Lsb start[2] = {0, 0};
    device::MotionDevice<2, 16> d(start);
    Map map(d);
    if ((in.byte() & 1u) != 0) (void)d.configure(fuzz::fuzz_limits<2>());
    hal::ModbusRtuSlave<Map> slave(map, kUnit);
    hal::ModbusRtuFramer framer(kT35);
    std::uint32_t now = 0xFFFF0000u;  // the clock wraps within a run
    std::vector<std::uint8_t> sent;   // the bytes since the last frame ended
    std::uint8_t reply[hal::kModbusRtuMaxFrame];
    while (!in.done()) {
        const std::uint8_t op = in.byte();
        if ((op & 0x80u) != 0) {
            // A frame's bytes without gaps: its unit ours, and its CRC made right, most of the
            // time, so that requests get past the first checks.
            std::vector<std::uint8_t> f(in.byte() % 40u + 1u);
            for (std::uint8_t& b : f) b = in.byte();
            if ((op & 0x20u) != 0) f[0] = kUnit;
            if ((op & 0x40u) != 0) {
                const std::uint16_t crc = crc_of(f.data(), f.size());
                f.push_back(static_cast<std::uint8_t>(crc & 0xFFu));
                f.push_back(static_cast<std::uint8_t>(crc >> 8));
            }
            for (const std::uint8_t b : f) {
                framer.on_byte(b, now);
                sent.push_back(b);
            }
        } else if ((op & 0x40u) != 0) {
            Lsb position[2];
            for (unsigned t = op % 16u; t > 0; --t) d.tick(position);
        } else {
            now += (op & 0x3Fu) * 100u;  // a silence of 0 to 6.3 ms
            if (framer.poll(now)) {
                const std::vector<std::uint8_t> frame(framer.frame(),
                                                      framer.frame() + framer.length());
                const auto before = fuzz::fingerprint(d);
                const std::size_t n = slave.handle(frame.data(), frame.size(), reply);
                framer.take();
                const bool crc_ok = frame.size() >= 4 &&
                                    crc_of(frame.data(), frame.size() - 2) ==
                                        static_cast<std::uint16_t>(frame[frame.size() - 2] |
                                                                   (frame[frame.size() - 1] << 8));
                if (!crc_ok && fuzz::fingerprint(d) != before)
                    fuzz::violated("a frame with a wrong CRC changed the device");
                if (n > 0) {
                    if (!crc_ok || frame[0] != kUnit) fuzz::violated("answered a frame not ours");
                    check_answer(frame, reply, n);
                }
                sent.clear();
            }
        }
    }
    return 0;
}
