// A Modbus RTU slave without libmodbus, for a firmware image: frames cut from the byte stream
// by the t3.5 silent interval, checked (CRC-16, unit), parsed (modbus_pdu.hpp), served by a
// ModbusRegisterHandler and answered. Freestanding: no heap, no exceptions, no OS headers;
// storage inline. Links pathstream::device for crc16_modbus (wire_span.hpp).
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/device/wire_span.hpp"
#include "pathstream/hal/modbus_pdu.hpp"
#include "pathstream/hal/modbus_register_handler.hpp"

namespace pathstream::hal {

/// Largest RTU frame: unit, 253-byte PDU, CRC (Modbus over serial line v1.02, 2.5.1.1).
inline constexpr std::size_t kModbusRtuMaxFrame = 256;

/// The silent interval that ends a frame, in microseconds: 3.5 characters of 11 bits at
/// `baud`, and the spec's fixed 1750 us above 19200 baud. `baud` > 0.
constexpr std::uint32_t modbus_rtu_t35_us(std::uint32_t baud) {
    if (baud > 19200u) return 1750u;
    return static_cast<std::uint32_t>((38500000ull + baud - 1u) / baud);  // 3.5 * 11 bits
}

/// Cuts frames out of received bytes: a frame ends at the silence of t3.5 after its last
/// byte, or at once when it is a request whose length its header gives (FC3, FC4, FC6: 8
/// bytes; FC16: 9 + byte count; FC23: 13 + write byte count) and that many bytes have come
/// with a right CRC. The second rule answers a request without waiting out the silence, so the
/// silence costs nothing per transaction and a line that pauses inside frames (an emulated
/// UART fed by a loaded host) can be given a longer one. One writer: on_byte and poll from the same
/// context (the UART interrupt feeding a ring the task drains, or the task polling the UART).
/// Time is any free-running 32-bit count that may wrap (microseconds, or a timer's counts);
/// the silence is given in the same unit.
class ModbusRtuFramer {
public:
    explicit constexpr ModbusRtuFramer(std::uint32_t silence) : silence_(silence) {}

    /// A byte arrived at `now`. A frame longer than kModbusRtuMaxFrame is dropped whole
    /// (its bytes are ignored up to the next silence). Cost: a compare, and one CRC of the
    /// frame when its length reaches the one its header announces.
    void on_byte(std::uint8_t byte, std::uint32_t now) {
        if (ready_) {  // a frame not taken before the next one began: the newer one wins
            ready_ = false;
            length_ = 0;
        }
        last_ = now;
        receiving_ = true;
        if (length_ < kModbusRtuMaxFrame) {
            frame_[length_++] = byte;
        } else {
            overflow_ = true;
        }
        if (!overflow_ && length_ >= 8 && length_ == request_length() &&
            device::crc16_modbus(frame_, length_ - 2) ==
                static_cast<std::uint16_t>(frame_[length_ - 2] | (frame_[length_ - 1] << 8))) {
            receiving_ = false;
            ready_ = true;
            ++early_;
        }
    }

    /// True once the frame is whole (see the class); the frame stays in frame()/length()
    /// until take() or the next byte. An overlong frame is never ready.
    constexpr bool poll(std::uint32_t now) {
        if (ready_) return true;
        if (!receiving_ || static_cast<std::uint32_t>(now - last_) < silence_) return false;
        receiving_ = false;
        if (overflow_) {
            overflow_ = false;
            length_ = 0;
            ++overflows_;
            return false;
        }
        ready_ = length_ > 0;
        return ready_;
    }

    const std::uint8_t* frame() const { return frame_; }
    std::size_t length() const { return length_; }
    /// The frame was handled: the next byte starts a new one.
    constexpr void take() {
        ready_ = false;
        length_ = 0;
    }
    /// Frames dropped for being longer than kModbusRtuMaxFrame.
    std::uint32_t overflows() const { return overflows_; }
    /// Frames ended by their announced length and CRC rather than by the silence.
    std::uint32_t ended_by_length() const { return early_; }

private:
    // The whole request's length as its header announces it, 0 when the function does not
    // say or the header has not come yet.
    constexpr std::size_t request_length() const {
        if (length_ < 2) return 0;
        switch (frame_[1]) {
            case 0x03:
            case 0x04:
            case 0x06:
                return 8;
            case 0x10:
                return length_ >= 7 ? 9u + frame_[6] : 0;
            case 0x17:
                return length_ >= 11 ? 13u + frame_[10] : 0;
            default:
                return 0;
        }
    }

    std::uint8_t frame_[kModbusRtuMaxFrame] = {};
    std::size_t length_ = 0;
    std::uint32_t silence_;
    std::uint32_t last_ = 0;
    std::uint32_t overflows_ = 0;
    std::uint32_t early_ = 0;
    bool receiving_ = false;
    bool overflow_ = false;
    bool ready_ = false;
};

/// What the slave did with one frame.
struct ModbusRtuCounters {
    std::uint32_t served = 0;      ///< requests answered (exceptions included)
    std::uint32_t exceptions = 0;  ///< of which exception responses
    std::uint32_t broadcasts = 0;  ///< unit-0 requests executed without an answer
    std::uint32_t bad_crc = 0;     ///< frames with a wrong CRC or under 4 bytes: ignored
    std::uint32_t other_unit = 0;  ///< frames for another unit: ignored
};

/// Serves one unit's registers over RTU frames. Task context; one request at a time.
/// `Handler` has ModbusRegisterHandler's four calls, returning any enum whose values are the
/// wire's exception codes (the device's ModbusRegisterMap, or a ModbusRegisterHandler): a
/// template, so that a firmware image has no vtable and no deleting destructor to link.
template <typename Handler>
class ModbusRtuSlave {
public:
    /// `unit` 1..247. The handler is not owned and outlives the slave.
    constexpr ModbusRtuSlave(Handler& handler, std::uint8_t unit)
        : handler_(handler), unit_(unit) {}

    /// Handles one whole frame (unit, PDU, CRC) and writes the answer into reply[0..256);
    /// returns its length, 0 when nothing is to be sent (bad CRC, another unit, broadcast).
    /// Cost: one CRC over the frame and one over the reply, and one handler call.
    std::size_t handle(const std::uint8_t* frame, std::size_t length, std::uint8_t* reply) {
        if (length < 4 || length > kModbusRtuMaxFrame ||
            device::crc16_modbus(frame, length - 2) !=
                static_cast<std::uint16_t>(frame[length - 2] | (frame[length - 1] << 8))) {
            ++counters_.bad_crc;
            return 0;
        }
        const std::uint8_t unit = frame[0];
        const bool broadcast = unit == 0;
        if (!broadcast && unit != unit_) {
            ++counters_.other_unit;
            return 0;
        }
        pdu::ModbusRequest request;
        std::uint8_t e =
            static_cast<std::uint8_t>(pdu::parse_modbus_request(frame + 1, length - 3, request));
        // A broadcast may only write (a read has nobody to answer to).
        if (broadcast && (e != 0 || !request.writes())) return 0;
        std::size_t n = 0;
        if (e == 0) e = serve(request, reply, n);
        if (broadcast) {
            ++counters_.broadcasts;
            return 0;
        }
        if (e != 0) {
            reply[1] = static_cast<std::uint8_t>(frame[1] | 0x80u);
            reply[2] = e;
            n = 3;
            ++counters_.exceptions;
        }
        reply[0] = unit_;
        const std::uint16_t crc = device::crc16_modbus(reply, n);
        reply[n] = static_cast<std::uint8_t>(crc & 0xFFu);
        reply[n + 1] = static_cast<std::uint8_t>(crc >> 8);
        ++counters_.served;
        return n + 2;
    }

    const ModbusRtuCounters& counters() const { return counters_; }

private:
    // Calls the handler for `r` and writes the answer's PDU at reply[1..n); returns the
    // exception code (0: none).
    std::uint8_t serve(const pdu::ModbusRequest& r, std::uint8_t* reply, std::size_t& n) {
        if (r.writes()) {
            const std::uint16_t count = r.function == pdu::kFcWriteRead ? r.write_count : r.count;
            for (std::uint16_t i = 0; i < count; ++i) values_[i] = pdu::load_be16(r.values + 2 * i);
        }
        std::uint8_t e = 0;
        reply[1] = r.function;
        switch (r.function) {
            case pdu::kFcReadHolding:
            case pdu::kFcReadInput:
                e = r.function == pdu::kFcReadInput
                        ? code(handler_.read_input_registers(r.address, r.count, out_))
                        : code(handler_.read_holding_registers(r.address, r.count, out_));
                n = registers_reply(reply, r.count);
                break;
            case pdu::kFcWriteRead:
                e = code(handler_.write_read_holding_registers(r.write_address, r.write_count,
                                                               values_, r.address, r.count, out_));
                n = registers_reply(reply, r.count);
                break;
            case pdu::kFcWriteSingle:
            case pdu::kFcWriteMultiple: {
                e = code(handler_.write_holding_registers(r.address, r.count, values_));
                // FC6 echoes address and value; FC16 answers address and count.
                const std::uint16_t second =
                    r.function == pdu::kFcWriteSingle ? values_[0] : r.count;
                put_be16(reply + 2, r.address);
                put_be16(reply + 4, second);
                n = 6;
                break;
            }
            default:
                e = static_cast<std::uint8_t>(ModbusException::kIllegalFunction);  // not parsed
                break;
        }
        return e;
    }

    template <typename Code>
    static constexpr std::uint8_t code(Code c) {
        return static_cast<std::uint8_t>(c);
    }

    std::size_t registers_reply(std::uint8_t* reply, std::uint16_t count) const {
        reply[2] = static_cast<std::uint8_t>(2u * count);
        for (std::uint16_t i = 0; i < count; ++i) put_be16(reply + 3 + 2 * i, out_[i]);
        return 3u + 2u * count;
    }

    static void put_be16(std::uint8_t* p, std::uint16_t v) {
        p[0] = static_cast<std::uint8_t>(v >> 8);
        p[1] = static_cast<std::uint8_t>(v & 0xFFu);
    }

    Handler& handler_;
    std::uint8_t unit_;
    std::uint16_t values_[pdu::kMaxWriteCount] = {};
    std::uint16_t out_[pdu::kMaxReadCount] = {};
    ModbusRtuCounters counters_;
};

}  // namespace pathstream::hal
