// The Modbus bus session: what SpanStreamer asks of a device, in registers.
#include "modbus_session.hpp"

#include <cmath>
#include <span>
#include <sstream>

#include "pathstream/device/modbus_map.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/status.hpp"

namespace pathstream::host {
namespace {
namespace mb = device::modbus;
namespace st = device::modbus::status;
}  // namespace

void ModbusSession::mark_alive() {
    link_.mark_alive();
    last_batch_ok_ = Clock::now();
}

DeviceSnapshot ModbusSession::read_status() {
    return link_.read_status(st::kStreamingCount);
}

void ModbusSession::check_protocol(const DeviceSnapshot& s) const {
    std::ostringstream m;
    if (s.magic != mb::kMagic) {
        m << "not a pathstream device (register 0 is 0x" << std::hex << s.magic
          << ", expected 0x5053)";
        fail(m.str());
    }
    if (s.version != mb::kProtocolVersion) {
        m << "device speaks protocol version " << s.version << ", this host "
          << mb::kProtocolVersion;
        fail(m.str());
    }
}

std::optional<std::string> ModbusSession::configure(const DeviceLimitsLsb& l, unsigned axes) {
    std::vector<std::uint16_t> r(mb::config_registers(axes), 0);
    const auto put32 = [&r](std::uint16_t at, std::uint32_t v) {
        r[at] = static_cast<std::uint16_t>(v >> 16);
        r[at + 1u] = static_cast<std::uint16_t>(v & 0xFFFFu);
    };
    put32(0, l.tick_hz);
    r[2] = static_cast<std::uint16_t>(axes);
    r[mb::kConfigPenDownTicks] = static_cast<std::uint16_t>(l.pen_down_ticks);
    for (unsigned a = 0; a < axes; ++a) {
        const auto base = static_cast<std::uint16_t>(mb::kConfigAxisBase + 4 * a);
        put32(base, l.max_velocity[a]);
        put32(static_cast<std::uint16_t>(base + 2), l.max_acceleration[a]);
        const std::uint16_t t = mb::config_travel_register(axes, a);
        put32(t, static_cast<std::uint32_t>(l.min_position[a]));
        put32(static_cast<std::uint16_t>(t + 2), static_cast<std::uint32_t>(l.max_position[a]));
        put32(mb::config_jerk_register(axes, a), l.max_jerk[a]);
    }
    try {
        link_.transact([&] { link_.client().write_registers(mb::kConfig, r); });
    } catch (const hal::ModbusError& e) {
        return std::string(e.what());
    }
    return std::nullopt;
}

std::optional<std::string> ModbusSession::command(device::Command c) {
    try {
        link_.write_command(c);
    } catch (const hal::ModbusError& e) {
        return std::string(e.what());
    }
    return std::nullopt;
}

std::size_t ModbusSession::batch_byte_limit() const {
    return 2u * mb::kMaxPayloadRegistersFc23;
}

BatchAnswer ModbusSession::send_batch(std::uint32_t first, std::size_t count,
                                      const std::vector<std::uint8_t>& payload) {
    std::vector<std::uint16_t> window = {
        static_cast<std::uint16_t>(first >> 16), static_cast<std::uint16_t>(first & 0xFFFFu),
        static_cast<std::uint16_t>(count), static_cast<std::uint16_t>(payload.size()),
        device::crc16_modbus(payload.data(), payload.size())};
    for (std::size_t i = 0; i < payload.size(); i += 2) {
        const std::uint16_t low = i + 1 < payload.size() ? payload[i + 1] : 0;
        window.push_back(static_cast<std::uint16_t>((payload[i] << 8) | low));
    }
    std::uint16_t r[st::kStreamingCount];
    const std::uint64_t retries_before = link_.client().counters().retries;
    BatchAnswer answer;
    try {
        link_.client().write_read_registers(mb::kSpanWindow, window, 0,
                                            std::span<std::uint16_t>(r, st::kStreamingCount));
    } catch (const hal::ModbusError& e) {
        if (e.exception_code() == static_cast<std::uint8_t>(mb::Exception::kServerDeviceBusy)) {
            answer.kind = BatchAnswer::Kind::kLater;  // queue fuller than we knew
            answer.status = read_status();
            return answer;
        }
        if (!e.transient()) {
            answer.kind = BatchAnswer::Kind::kRefused;
            answer.reason = e.what();
            answer.status = read_status();
            return answer;
        }
        // The batch may or may not have been applied (a lost response). Resend nothing blind:
        // the streamer asks the device what it accepted, and smaller batches follow, which a
        // noisy line lets through far more often (each byte is a chance to lose the frame).
        shrink_batches(count);
        const double silent = std::chrono::duration<double>(Clock::now() - last_batch_ok_).count();
        if (silent > options_.link_timeout_seconds) {
            std::ostringstream m;
            m << "no batch got through for " << std::lround(silent) << " s (" << e.what() << ")";
            fail(m.str());
        }
        answer.kind = BatchAnswer::Kind::kUnknown;
        answer.status = read_status();
        return answer;
    }
    link_.mark_alive();
    last_batch_ok_ = Clock::now();
    if (link_.client().counters().retries != retries_before) {
        shrink_batches(count);
    } else if (++clean_batches_ >= kCleanBatchesToGrow && batch_limit_ < device::kMaxBatchSpans) {
        batch_limit_ = std::min<std::size_t>(device::kMaxBatchSpans, 2 * batch_limit_);
        clean_batches_ = 0;
    }
    answer.status = parse_modbus_status(r, st::kStreamingCount);
    return answer;
}

// After a batch that needed a retry: at most half as many spans per batch from now on.
void ModbusSession::shrink_batches(std::size_t count) {
    batch_limit_ = std::max<std::size_t>(1, std::min(batch_limit_, count) / 2);
    clean_batches_ = 0;
}

std::string ModbusSession::refusal_note(const DeviceSnapshot& s) const {
    return std::string(" [device: ") + status_name(static_cast<Status>(s.last_refusal)) + "]";
}

void ModbusSession::count_into(StreamReport& report) const {
    const auto& c = link_.client().counters();
    report.transactions = c.transactions;
    report.retries = c.retries;
    report.attempts = c.attempts;
    report.exception_responses = c.exception_responses;
    report.reconnects = c.reconnects;
    report.bytes_sent = c.adu_bytes_sent;
    report.bytes_received = c.adu_bytes_received;
    report.status_reads = link_.status_reads();
}

}  // namespace pathstream::host
