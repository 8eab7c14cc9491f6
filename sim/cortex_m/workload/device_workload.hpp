// The device section of the shared workload: MotionDevice and its Modbus register map driven
// exactly as a bus would drive them (register writes and reads), compiled unchanged for the
// host and for the Cortex-M images, so the state machine, the exact limit check, the
// controlled stops and the register map are proven freestanding and bit-identical on target.
//
// Spans are integer random walks in velocity: each span of 8 ticks changes every axis's
// velocity (LSB/tick) by at most 2 and keeps it within +/-50, with P1 - P0 = (T0 + T1) / 2
// (the trapezoid rule, exact), so the cubic is a parabola whose acceleration is within the
// configured limits. Batches go through the span window with a CRC; deliberate faults (a bad
// check value, a wrong sequence, a span over the limits, a full queue) must each be refused
// with their exception and change nothing. The run holds, resumes, lets the queue run dry
// (the device stops by itself), resumes again, and ends with an e-stop and a reset.
#pragma once

#include <cstdint>

#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"

namespace pathstream::workload {

template <unsigned Axes>
class DeviceWorkload {
public:
    static constexpr std::uint32_t kCapacity = 16;
    using Map = device::ModbusRegisterMap<Axes, kCapacity>;
    using Ex = device::modbus::Exception;

    explicit DeviceWorkload(Context& ctx) : ctx_(ctx), device_(origin()), map_(device_) {}

    void run() {
        configure();
        for (unsigned a = 0; a < Axes; ++a) position_[a] = 0;
        send_batches(6);
        command(device::Command::kStart, Ex::kNone);
        fault_batches();
        for (int round = 0; round < 40; ++round) {
            send_batches(1);
            ticks(40);
        }
        command(device::Command::kHold, Ex::kNone);
        ticks(300);
        expect_state(device::DeviceState::kHolding);
        command(device::Command::kResume, Ex::kNone);
        for (int round = 0; round < 20; ++round) {
            send_batches(1);
            ticks(40);
        }
        ticks(600);  // starved: a controlled stop by itself
        expect_state(device::DeviceState::kHolding);
        if (!device_.held_by_underrun()) ++ctx_.summary.mismatches;
        send_batches(2);
        command(device::Command::kResume, Ex::kNone);
        ticks(900);
        device_.set_estop_input(true);
        ticks(3);
        expect_state(device::DeviceState::kEstop);
        command(device::Command::kReset, Ex::kServerDeviceFailure);  // input still active
        device_.set_estop_input(false);
        command(device::Command::kReset, Ex::kNone);
        ticks(2);
        expect_state(device::DeviceState::kIdle);
        hash_status();
    }

private:
    static const Lsb (&origin())[Axes] {
        static const Lsb zero[Axes] = {};
        return zero;
    }

    void configure() {
        std::uint16_t r[device::modbus::config_registers(Axes)] = {};
        r[1] = 1000;  // tick rate, low word
        r[2] = Axes;
        for (unsigned a = 0; a < Axes; ++a) {
            r[device::modbus::kConfigAxisBase + 4 * a + 1] = 60000;  // 60,000 LSB/s
            r[device::modbus::kConfigAxisBase + 4 * a + 2] =
                4;  // 4 * 65536 + 37856 = 300,000 LSB/s^2
            r[device::modbus::kConfigAxisBase + 4 * a + 3] = 37856;
        }
        check(map_.write_holding_registers(device::modbus::kConfig,
                                           device::modbus::config_registers(Axes), r),
              Ex::kNone);
    }

    // Next span of the random walk (8 ticks), advancing the walk.
    device::WireSpan next_span() {
        device::WireSpan w;
        w.ticks = 8;
        w.flags = device::kWireContinueTangent;
        w.outputs = static_cast<std::uint8_t>(ctx_.rng.below(2));
        for (unsigned a = 0; a < Axes; ++a) {
            std::int32_t v1 = velocity_[a] + ctx_.rng.between(-2, 2);
            if (v1 > 50) v1 = 50;
            if (v1 < -50) v1 = -50;
            const std::int32_t t0 = velocity_[a] * 8, t1 = v1 * 8;
            position_[a] += (t0 + t1) / 2;
            w.end[a] = position_[a];
            w.end_tangent[a] = t1;
            velocity_[a] = v1;
        }
        return w;
    }

    // Encodes `count` spans into a span-window register block; returns its register count.
    std::uint16_t window(std::uint32_t first, std::uint16_t count, std::uint16_t (&r)[123]) {
        std::uint8_t bytes[2 * 118] = {};
        std::size_t length = 0;
        for (std::uint16_t i = 0; i < count; ++i) {
            const device::WireSpan w = next_span();
            length += device::encode_wire_span(w, Axes, bytes + length, sizeof bytes - length);
        }
        r[0] = static_cast<std::uint16_t>(first >> 16);
        r[1] = static_cast<std::uint16_t>(first & 0xFFFFu);
        r[2] = count;
        r[3] = static_cast<std::uint16_t>(length);
        r[4] = device::crc16_modbus(bytes, length);
        const std::size_t words = (length + 1) / 2;
        for (std::size_t i = 0; i < words; ++i) {
            r[5 + i] = static_cast<std::uint16_t>((bytes[2 * i] << 8) | bytes[2 * i + 1]);
        }
        return static_cast<std::uint16_t>(5 + words);
    }

    std::uint16_t spans_per_batch() const {
        const std::size_t per = device::wire_span_bytes(Axes, true);
        const std::size_t fit = (2 * 116) / per;
        return static_cast<std::uint16_t>(fit < 4 ? fit : 4);
    }

    void send_batches(int batches) {
        for (int b = 0; b < batches; ++b) {
            const std::uint16_t count = spans_per_batch();
            if (device_.free_slots() < count) return;
            std::uint16_t r[123] = {};
            const std::uint16_t n = window(next_sequence_, count, r);
            check(map_.write_holding_registers(device::modbus::kSpanWindow, n, r), Ex::kNone);
            next_sequence_ += count;
            ctx_.summary.spans_accepted += count;
        }
    }

    // Each refused write must leave the device as it was (same status block).
    void fault_batches() {
        std::uint16_t before[device::modbus::status::kCount];
        check(map_.read_input_registers(0, device::modbus::status::kCount, before), Ex::kNone);
        std::int32_t keep_p[Axes], keep_v[Axes];
        for (unsigned a = 0; a < Axes; ++a) {
            keep_p[a] = position_[a];
            keep_v[a] = velocity_[a];
        }
        std::uint16_t r[123] = {};
        std::uint16_t n = window(next_sequence_, 2, r);
        r[4] ^= 1u;  // wrong check value
        check(map_.write_holding_registers(device::modbus::kSpanWindow, n, r),
              Ex::kIllegalDataValue);
        restore(keep_p, keep_v);
        n = window(next_sequence_ + 5, 2, r);  // sequence gap
        check(map_.write_holding_registers(device::modbus::kSpanWindow, n, r),
              Ex::kIllegalDataValue);
        restore(keep_p, keep_v);
        // A span far over the acceleration limit: end tangent jumps by 400 LSB/tick.
        device::WireSpan w = next_span();
        w.end_tangent[0] += 3200;
        std::uint8_t bytes[4 + 12 * 8];
        const std::size_t length = device::encode_wire_span(w, Axes, bytes, sizeof bytes);
        r[0] = static_cast<std::uint16_t>(next_sequence_ >> 16);
        r[1] = static_cast<std::uint16_t>(next_sequence_ & 0xFFFFu);
        r[2] = 1;
        r[3] = static_cast<std::uint16_t>(length);
        r[4] = device::crc16_modbus(bytes, length);
        for (std::size_t i = 0; i < (length + 1) / 2; ++i) {
            r[5 + i] = static_cast<std::uint16_t>((bytes[2 * i] << 8) |
                                                  (2 * i + 1 < length ? bytes[2 * i + 1] : 0));
        }
        check(map_.write_holding_registers(device::modbus::kSpanWindow,
                                           static_cast<std::uint16_t>(5 + (length + 1) / 2), r),
              Ex::kIllegalDataValue);
        restore(keep_p, keep_v);
        std::uint16_t after[device::modbus::status::kCount];
        check(map_.read_input_registers(0, device::modbus::status::kCount, after), Ex::kNone);
        // Everything but the refusal bookkeeping must be unchanged.
        for (std::uint16_t i = 0; i < device::modbus::status::kLastRefusal; ++i) {
            if (before[i] != after[i]) ++ctx_.summary.mismatches;
        }
        ctx_.summary.spans_rejected += 3;
    }

    void restore(const std::int32_t (&p)[Axes], const std::int32_t (&v)[Axes]) {
        for (unsigned a = 0; a < Axes; ++a) {
            position_[a] = p[a];
            velocity_[a] = v[a];
        }
    }

    void command(device::Command c, Ex expected) {
        const std::uint16_t value = static_cast<std::uint16_t>(c);
        check(map_.write_holding_registers(device::modbus::kCommand, 1, &value), expected);
    }

    void ticks(int count) {
        for (int i = 0; i < count; ++i) {
            Lsb out[Axes];
            device_.tick(out);
            ++ctx_.summary.ticks;
            for (unsigned a = 0; a < Axes; ++a) {
                ctx_.hash.lsb(out[a]);
                // The axes never move faster than the configured 60 LSB per tick (+1 rounding).
                const std::int32_t step = out[a] - last_[a];
                if (step > 61 || step < -61) ++ctx_.summary.mismatches;
                last_[a] = out[a];
            }
            ctx_.hash.u32(static_cast<std::uint32_t>(device_.state()) |
                          (static_cast<std::uint32_t>(device_.outputs()) << 8));
        }
    }

    void expect_state(device::DeviceState s) {
        if (device_.state() != s) ++ctx_.summary.mismatches;
    }

    void check(Ex got, Ex expected) {
        ctx_.hash.u32(static_cast<std::uint32_t>(got));
        if (got != expected) ++ctx_.summary.mismatches;
    }

    void hash_status() {
        std::uint16_t s[device::modbus::status::kCount];
        check(map_.read_input_registers(0, device::modbus::status::kCount, s), Ex::kNone);
        for (std::uint16_t v : s) ctx_.hash.u32(v);
    }

    Context& ctx_;
    device::MotionDevice<Axes, kCapacity> device_;
    Map map_;
    std::uint32_t next_sequence_ = 1;
    std::int32_t position_[Axes] = {};
    std::int32_t velocity_[Axes] = {};
    Lsb last_[Axes] = {};
};

}  // namespace pathstream::workload
