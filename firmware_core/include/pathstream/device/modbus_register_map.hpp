// The device's Modbus register map (modbus_map.hpp) over a MotionDevice: the protocol logic
// of a Modbus device, independent of the transport. Every write is validated in full before
// anything changes; a refused write answers an exception and leaves the device as it was.
#pragma once

#include <cstdint>

#include "pathstream/device/modbus_map.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/operator_commands.hpp"

namespace pathstream::device {

/// Serves MotionDevice<Axes, Capacity> as Modbus registers. Methods mirror a transport's
/// register handler (hal::ModbusRegisterHandler): addresses and counts already checked for
/// shape by the transport; the map decides meaning. Task context (the bus server), the same
/// task that owns the device's producer side. No allocation; two 246-byte payload buffers
/// inline (the batch being written and the last one queued: a resend is compared byte for
/// byte, and one under the same sequence numbers with other bytes is refused).
template <unsigned Axes, std::uint32_t Capacity>
class ModbusRegisterMap {
public:
    using Exception = modbus::Exception;

    explicit ModbusRegisterMap(MotionDevice<Axes, Capacity>& device)
        : device_(device), operator_(device) {}

    /// Task loop: feeds a jog in progress (call at least once per span period).
    void service() { operator_.service(); }

    /// The commands with arguments (the port connects its homing here).
    OperatorCommands<Axes, Capacity>& operator_commands() { return operator_; }

    /// FC4: registers of the status block. Addresses outside it: kIllegalDataAddress.
    Exception read_input_registers(std::uint16_t address, std::uint16_t count, std::uint16_t* out) {
        if (static_cast<std::uint32_t>(address) + count > modbus::status::kCount) {
            return Exception::kIllegalDataAddress;
        }
        std::uint16_t block[modbus::status::kCount];
        fill_status(block);
        for (std::uint16_t i = 0; i < count; ++i) out[i] = block[address + i];
        return Exception::kNone;
    }

    /// FC3: the status mirror, the command register, the configuration block. Anything else,
    /// the span window included (a write-only mailbox): kIllegalDataAddress.
    Exception read_holding_registers(std::uint16_t address, std::uint16_t count,
                                     std::uint16_t* out) {
        const std::uint32_t end = static_cast<std::uint32_t>(address) + count;
        if (end <= modbus::status::kCount) return read_input_registers(address, count, out);
        if (address == modbus::kCommand && count == 1) {
            out[0] = last_command_;
            return Exception::kNone;
        }
        const std::uint32_t config_end = modbus::kConfig + modbus::config_registers(Axes);
        if (address >= modbus::kConfig && end <= config_end) {
            std::uint16_t block[modbus::config_registers(kMaxAxes)];
            fill_config(block);
            for (std::uint16_t i = 0; i < count; ++i) out[i] = block[address - modbus::kConfig + i];
            return Exception::kNone;
        }
        return Exception::kIllegalDataAddress;
    }

    /// FC6/FC16: the command register (one value), the whole configuration block, or a whole
    /// batch in the span window. All or nothing. The refusal's core Status is kept in the
    /// status block (kLastRefusal) so a master can tell why.
    Exception write_holding_registers(std::uint16_t address, std::uint16_t count,
                                      const std::uint16_t* values) {
        Status s = Status::kOk;
        Exception e = Exception::kNone;
        if (address == modbus::kCommand && count == 1) {
            // Any value goes to the core, which refuses what is no command (kUnknownCommand).
            s = device_.command(static_cast<Command>(values[0]));
            if (s == Status::kOk) last_command_ = values[0];
        } else if (address == modbus::kCommand && count == modbus::kCommandWithArguments) {
            s = command_with_arguments(values);
            if (s == Status::kOk) last_command_ = values[0];
        } else if (address == modbus::kConfig && count == modbus::config_registers(Axes)) {
            s = write_config(values, e);
        } else if (address == modbus::kSpanWindow && count >= modbus::kSpanHeaderRegisters) {
            s = write_batch(values, count, e);
        } else {
            e = Exception::kIllegalDataAddress;
        }
        if (e == Exception::kNone && s != Status::kOk) e = exception_for(s);
        if (e != Exception::kNone) {
            last_refusal_ = static_cast<std::uint16_t>(s);
            ++refusals_;
        }
        return e;
    }

    /// FC23: checks the read range first, then writes, then reads (so a refused read never
    /// follows an applied write).
    Exception write_read_holding_registers(std::uint16_t write_address, std::uint16_t write_count,
                                           const std::uint16_t* values, std::uint16_t read_address,
                                           std::uint16_t read_count, std::uint16_t* out) {
        if (read_holding_registers(read_address, read_count, out) != Exception::kNone) {
            return Exception::kIllegalDataAddress;
        }
        const Exception e = write_holding_registers(write_address, write_count, values);
        if (e != Exception::kNone) return e;
        return read_holding_registers(read_address, read_count, out);
    }

    /// Writes refused since construction.
    std::uint16_t refusals() const { return refusals_; }

    /// The exception a refused write answers with, from the core's Status (docs/modbus.md,
    /// "Validation and exceptions"). Any context; no side effects.
    static Exception exception_for(Status s) {
        switch (s) {
            case Status::kQueueFull:
                return Exception::kServerDeviceBusy;
            case Status::kNotConfigured:
            case Status::kWrongState:
            case Status::kNothingToResume:
                return Exception::kServerDeviceFailure;
            default:
                return Exception::kIllegalDataValue;
        }
    }

private:
    static std::uint32_t u32(const std::uint16_t* r) {
        return (static_cast<std::uint32_t>(r[0]) << 16) | r[1];
    }
    static void put_u32(std::uint16_t* r, std::uint32_t v) {
        r[0] = static_cast<std::uint16_t>(v >> 16);
        r[1] = static_cast<std::uint16_t>(v & 0xFFFFu);
    }

    // One status read: every tick-side register comes from the same tick.
    void fill_status(std::uint16_t (&b)[modbus::status::kCount]) const {
        namespace st = modbus::status;
        const DeviceStatus<Axes> s = device_.status();
        for (auto& r : b) r = 0;
        b[st::kMagic] = modbus::kMagic;
        b[st::kVersion] = modbus::kProtocolVersion;
        b[st::kState] = static_cast<std::uint16_t>(s.state);
        b[st::kFaultCode] = static_cast<std::uint16_t>(s.fault_code);
        b[st::kFreeSlots] = static_cast<std::uint16_t>(device_.free_slots());
        b[st::kCapacity] = static_cast<std::uint16_t>(Capacity);
        put_u32(&b[st::kLastAcceptedSequence], device_.last_accepted_sequence());
        put_u32(&b[st::kTicksExecuted], s.ticks_executed_low);
        for (unsigned a = 0; a < Axes; ++a)
            put_u32(&b[st::kPositions + 2 * a], static_cast<std::uint32_t>(s.position[a]));
        b[st::kAxes] = static_cast<std::uint16_t>(Axes);
        b[st::kUnderruns] = static_cast<std::uint16_t>(s.underruns & 0xFFFFu);
        put_u32(&b[st::kLastCompletedSequence], s.last_completed_sequence);
        b[st::kLastRefusal] = last_refusal_;
        b[st::kRefusals] = refusals_;
        b[st::kDuplicates] = static_cast<std::uint16_t>(device_.duplicates() & 0xFFFFu);
        b[st::kOutputs] = static_cast<std::uint16_t>(s.outputs);
        b[st::kQueuedSpans] = static_cast<std::uint16_t>(device_.queued_spans());
        b[st::kFlags] = static_cast<std::uint16_t>(
            (device_.configured() ? modbus::flags::kConfigured : 0u) |
            (s.held_by_underrun() ? modbus::flags::kHeldByUnderrun : 0u) |
            (s.own_move() ? modbus::flags::kOwnMove : 0u) |
            (s.paused() ? modbus::flags::kPaused : 0u) |
            (operator_.homing() ? modbus::flags::kHoming : 0u));
        put_u32(&b[st::kFinishedJob], s.finished_job);
        put_u32(&b[st::kFinishedJobTicks], s.finished_job_ticks);
        put_u32(&b[st::kEpoch], s.epoch);
        for (unsigned a = 0; a < Axes; ++a) {
            const HomingReport h = operator_.homing_report(a);
            b[st::kHoming + a] = static_cast<std::uint16_t>(static_cast<unsigned>(h.state) |
                                                            (static_cast<unsigned>(h.error) << 8));
        }
    }

    void fill_config(std::uint16_t (&b)[modbus::config_registers(kMaxAxes)]) const {
        for (auto& r : b) r = 0;
        const MotionLimits<Axes>& l = device_.limits();
        put_u32(&b[0], l.tick_hz);
        b[2] = static_cast<std::uint16_t>(Axes);
        b[modbus::kConfigPenDownTicks] = static_cast<std::uint16_t>(l.pen_down_ticks);
        for (unsigned a = 0; a < Axes; ++a) {
            put_u32(&b[modbus::kConfigAxisBase + 4 * a], l.axis[a].max_velocity);
            put_u32(&b[modbus::kConfigAxisBase + 4 * a + 2], l.axis[a].max_acceleration);
            const std::uint16_t t = modbus::config_travel_register(Axes, a);
            put_u32(&b[t], static_cast<std::uint32_t>(l.axis[a].min_position));
            put_u32(&b[t + 2], static_cast<std::uint32_t>(l.axis[a].max_position));
            put_u32(&b[modbus::config_jerk_register(Axes, a)], l.axis[a].max_jerk);
        }
    }

    // 6 jog, 7 set position, 8 home, 9 pen; any other value here is kUnknownCommand.
    Status command_with_arguments(const std::uint16_t* v) {
        if (v[0] > 0xFFu) return Status::kUnknownCommand;
        OperatorCommand c;
        c.command = static_cast<std::uint8_t>(v[0]);
        c.axis = v[1];
        c.value = static_cast<std::int32_t>(u32(&v[2]));
        c.feed = v[4];
        return operator_.execute(c);
    }

    Status write_config(const std::uint16_t* v, Exception& e) {
        if (v[2] != Axes) {
            e = Exception::kIllegalDataValue;
            return Status::kBadLimits;
        }
        for (std::uint16_t i = modbus::kConfigPenDownTicks + 1; i < modbus::kConfigAxisBase; ++i) {
            if (v[i] != 0) {
                e = Exception::kIllegalDataValue;
                return Status::kBadLimits;
            }
        }
        MotionLimits<Axes> l;
        l.tick_hz = u32(&v[0]);
        l.pen_down_ticks = v[modbus::kConfigPenDownTicks];
        for (unsigned a = 0; a < Axes; ++a) {
            l.axis[a].max_velocity = u32(&v[modbus::kConfigAxisBase + 4 * a]);
            l.axis[a].max_acceleration = u32(&v[modbus::kConfigAxisBase + 4 * a + 2]);
            const std::uint16_t t = modbus::config_travel_register(Axes, a);
            // 0, 0: no travel limits (a host that does not set them writes zeros).
            if (u32(&v[t]) != 0 || u32(&v[t + 2]) != 0) {
                l.axis[a].min_position = static_cast<std::int32_t>(u32(&v[t]));
                l.axis[a].max_position = static_cast<std::int32_t>(u32(&v[t + 2]));
            }
            l.axis[a].max_jerk = u32(&v[modbus::config_jerk_register(Axes, a)]);
        }
        return device_.configure(l);
    }

    Status write_batch(const std::uint16_t* v, std::uint16_t count, Exception& e) {
        const std::uint32_t first = u32(&v[0]);
        const std::uint16_t spans = v[2];
        const std::uint16_t bytes = v[3];
        const std::uint16_t check = v[4];
        const std::uint16_t payload_registers =
            static_cast<std::uint16_t>(count - modbus::kSpanHeaderRegisters);
        // The payload must fill exactly its registers (one pad byte at most).
        if (bytes > 2u * payload_registers || bytes + 1u < 2u * payload_registers ||
            bytes > sizeof payload_) {
            e = Exception::kIllegalDataValue;
            return Status::kBadBatch;
        }
        for (std::uint16_t i = 0; i < payload_registers; ++i) {
            const std::uint16_t r = v[modbus::kSpanHeaderRegisters + i];
            payload_[2 * i] = static_cast<std::uint8_t>(r >> 8);
            payload_[2 * i + 1] = static_cast<std::uint8_t>(r & 0xFFu);
        }
        if ((bytes & 1u) != 0 && payload_[bytes] != 0) {
            e = Exception::kIllegalDataValue;
            return Status::kBadBatch;
        }
        if (crc16_modbus(payload_, bytes) != check) {
            e = Exception::kIllegalDataValue;
            return Status::kBadBatch;
        }
        return device_.accept_batch(first, spans, payload_, bytes);
    }

    MotionDevice<Axes, Capacity>& device_;
    OperatorCommands<Axes, Capacity> operator_;
    std::uint8_t payload_[2 * 123] = {};
    std::uint16_t last_command_ = 0;
    std::uint16_t last_refusal_ = 0;
    std::uint16_t refusals_ = 0;
};

}  // namespace pathstream::device
