#include "pathstream/hal/modbus_client.hpp"

#include <modbus/modbus.h>
#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <stdexcept>
#include <string>

#include "pathstream/hal/modbus_adu.hpp"

namespace pathstream::hal {
namespace {

using std::chrono::milliseconds;

void set_timeout(modbus_t* ctx, milliseconds timeout,
                 int (*setter)(modbus_t*, std::uint32_t, std::uint32_t)) {
    const auto us = std::chrono::duration_cast<std::chrono::microseconds>(timeout).count();
    setter(ctx, static_cast<std::uint32_t>(us / 1'000'000),
           static_cast<std::uint32_t>(us % 1'000'000));
}

// libmodbus reports through errno: its own codes above MODBUS_ENOBASE, the OS's below.
ModbusError classify(int err, const std::string& context, milliseconds response_timeout) {
    using Kind = ModbusError::Kind;
    if (err == ETIMEDOUT) {
        return {Kind::kTimeout, context + ": timeout (no complete response within " +
                                    std::to_string(response_timeout.count()) + " ms)"};
    }
    if (err >= EMBXILFUN && err <= EMBXGTAR) {
        const auto code = static_cast<std::uint8_t>(err - MODBUS_ENOBASE);
        return {Kind::kExceptionResponse,
                context + ": exception response " + std::to_string(code) + " (" +
                    modbus_exception_name(code) + ")",
                code};
    }
    if (err == EMBBADCRC || err == EMBBADDATA || err == EMBBADEXC || err == EMBUNKEXC ||
        err == EMBMDATA || err == EMBBADSLAVE) {
        return {Kind::kBadFrame, context + ": bad frame (" + modbus_strerror(err) + ")"};
    }
    return {Kind::kConnectionLost, context + ": connection lost (" + modbus_strerror(err) + ")"};
}

void check_count(const char* what, std::size_t count, std::size_t max) {
    if (count < 1 || count > max) {
        throw std::invalid_argument(std::string(what) + ": " + std::to_string(count) +
                                    " registers is not in 1.." + std::to_string(max));
    }
}

void check_range(const char* what, std::uint16_t address, std::size_t count) {
    if (address + count > 0x10000u) {
        throw std::invalid_argument(std::string(what) + ": registers " + std::to_string(address) +
                                    ".." + std::to_string(address + count - 1) + " run past 65535");
    }
}

}  // namespace

struct ModbusClient::Impl {
    ModbusTarget target;
    ModbusClientOptions options;
    ModbusFraming framing;
    std::string name;  // the canonical URL, for messages
    modbus_t* ctx = nullptr;
    bool open = false;
    bool ever_connected = false;
    ModbusClientCounters counters;

    Impl(const ModbusTarget& t, const ModbusClientOptions& o)
        : target(t),
          options(o),
          framing(t.transport == ModbusTarget::Transport::kTcp ? ModbusFraming::kTcp
                                                               : ModbusFraming::kRtu),
          name(to_string(t)) {
        if (options.attempts < 1)
            throw std::invalid_argument("ModbusClient: attempts must be >= 1");
        if (framing == ModbusFraming::kTcp) {
            const std::string port = std::to_string(target.port);
            ctx = modbus_new_tcp_pi(target.host.c_str(), port.c_str());
        } else {
            const ModbusSerialLine& s = target.serial;
            ctx = modbus_new_rtu(s.device.c_str(), s.baud, s.parity, s.data_bits, s.stop_bits);
        }
        if (ctx == nullptr) {
            throw std::invalid_argument(name + ": libmodbus refused the settings (" +
                                        modbus_strerror(errno) + ")");
        }
        modbus_set_slave(ctx, target.unit);
        // Never let libmodbus reconnect or flush on its own: LINK recovery loops on a dead
        // peer (libmodbus issues #734, #735); the retry loop below owns recovery.
        modbus_set_error_recovery(ctx, MODBUS_ERROR_RECOVERY_NONE);
        set_timeout(ctx, options.response_timeout, modbus_set_response_timeout);
        set_timeout(ctx, options.byte_timeout, modbus_set_byte_timeout);
    }

    ~Impl() {
        disconnect();
        modbus_free(ctx);
    }

    // `context` starts the message: the URL, and the transaction when one needed the connect.
    void connect(const std::string& context) {
        if (modbus_connect(ctx) != 0) {
            const int err = errno;
            ++counters.connect_failures;
            throw ModbusError(ModbusError::Kind::kConnectFailed,
                              context + ": cannot connect (" + modbus_strerror(err) + ")", 0, err);
        }
        open = true;
        if (ever_connected) ++counters.reconnects;
        ever_connected = true;
    }

    void disconnect() {
        if (open) modbus_close(ctx);
        open = false;
    }

    // RTU after a failed try: drop what is buffered, then keep dropping until the line has
    // been quiet for a while, so that a late response to this try cannot be read as the
    // response to the next. Bounded by one response timeout.
    void settle_serial_line() {
        modbus_flush(ctx);
        const milliseconds quiet =
            std::clamp(options.response_timeout / 10, milliseconds(2), milliseconds(50));
        const auto deadline = std::chrono::steady_clock::now() + options.response_timeout;
        pollfd fd{modbus_get_socket(ctx), POLLIN, 0};
        while (std::chrono::steady_clock::now() < deadline &&
               ::poll(&fd, 1, static_cast<int>(quiet.count())) > 0) {
            if ((fd.revents & POLLIN) == 0) break;  // hang-up / error: nothing to drain
            modbus_flush(ctx);
        }
    }

    // Runs `op` (a libmodbus call returning -1 on failure) under the retry policy.
    // request_pdu / response_pdu size the byte counters.
    template <class Op>
    void transact(const std::string& what, std::size_t request_pdu, std::size_t response_pdu,
                  Op op) {
        const std::string context = name + ": " + what;
        const std::uint64_t request_adu = modbus_adu_bytes(framing, request_pdu);
        for (int attempt = 1;; ++attempt) {
            ++counters.attempts;
            if (attempt > 1) ++counters.retries;
            ModbusError failure(ModbusError::Kind::kConnectFailed, "");
            try {
                if (!open) connect(context);
                errno = 0;
                if (op(ctx) != -1) {
                    counters.adu_bytes_sent += request_adu;
                    counters.adu_bytes_received += modbus_adu_bytes(framing, response_pdu);
                    ++counters.transactions;
                    return;
                }
                failure = classify(errno, context, options.response_timeout);
            } catch (const ModbusError& e) {  // connect failed
                failure = e;
            }
            switch (failure.kind()) {
                case ModbusError::Kind::kExceptionResponse:
                    ++counters.exception_responses;
                    counters.adu_bytes_sent += request_adu;
                    counters.adu_bytes_received +=
                        modbus_adu_bytes(framing, modbus_exception_pdu_bytes());
                    throw failure;  // a definite answer: retrying cannot change it
                case ModbusError::Kind::kTimeout:
                    ++counters.timeouts;
                    counters.adu_bytes_sent += request_adu;
                    break;
                case ModbusError::Kind::kBadFrame:
                    ++counters.bad_frames;
                    counters.adu_bytes_sent += request_adu;
                    break;
                case ModbusError::Kind::kConnectionLost:
                    ++counters.connection_losses;
                    break;
                case ModbusError::Kind::kConnectFailed:
                    break;  // counted in connect()
            }
            if (open) {
                if (framing == ModbusFraming::kTcp ||
                    failure.kind() == ModbusError::Kind::kConnectionLost) {
                    disconnect();  // the next try (or call) starts on a fresh connection
                } else {
                    settle_serial_line();
                }
            }
            if (attempt >= options.attempts) {
                if (options.attempts == 1) throw failure;
                throw ModbusError(
                    failure.kind(),
                    std::string(failure.what()) + " (after " + std::to_string(attempt) + " tries)",
                    failure.exception_code());
            }
        }
    }

    bool broadcast() const { return framing == ModbusFraming::kRtu && target.unit == 0; }

    // Reads, and the coil writes (an output must be confirmed), need an answer.
    void refuse_broadcast(const char* what) const {
        if (broadcast()) {
            throw std::invalid_argument(name + ": " + what +
                                        " to the broadcast unit 0 (nobody answers)");
        }
    }

    // A broadcast write: one send, no response to wait for (Modbus over serial line 2.1).
    void send_broadcast(const std::string& what, std::uint8_t* raw, int length) {
        ++counters.attempts;
        if (!open) connect(name + ": " + what);
        const int sent = modbus_send_raw_request(ctx, raw, length);
        if (sent < 0) {
            const ModbusError failure =
                classify(errno, name + ": " + what, options.response_timeout);
            ++counters.connection_losses;
            disconnect();
            throw failure;
        }
        counters.adu_bytes_sent += static_cast<std::uint64_t>(sent);
        ++counters.transactions;
    }
};

ModbusClient::ModbusClient(const ModbusTarget& target, const ModbusClientOptions& options)
    : impl_(std::make_unique<Impl>(target, options)) {
    impl_->connect(impl_->name);
}

ModbusClient::ModbusClient(std::string_view url, const ModbusClientOptions& options)
    : ModbusClient(parse_modbus_target(url), options) {}

ModbusClient::~ModbusClient() = default;
ModbusClient::ModbusClient(ModbusClient&&) noexcept = default;
ModbusClient& ModbusClient::operator=(ModbusClient&&) noexcept = default;

void ModbusClient::read_input_registers(std::uint16_t address, std::span<std::uint16_t> out) {
    check_count("read_input_registers", out.size(), 125);
    check_range("read_input_registers", address, out.size());
    impl_->refuse_broadcast("read_input_registers");
    const int n = static_cast<int>(out.size());
    impl_->transact(
        "FC4 read input registers " + std::to_string(address) + " x" + std::to_string(n),
        modbus_read_request_pdu_bytes(), modbus_read_response_pdu_bytes(out.size()),
        [&](modbus_t* ctx) { return modbus_read_input_registers(ctx, address, n, out.data()); });
}

void ModbusClient::read_holding_registers(std::uint16_t address, std::span<std::uint16_t> out) {
    check_count("read_holding_registers", out.size(), 125);
    check_range("read_holding_registers", address, out.size());
    impl_->refuse_broadcast("read_holding_registers");
    const int n = static_cast<int>(out.size());
    impl_->transact(
        "FC3 read holding registers " + std::to_string(address) + " x" + std::to_string(n),
        modbus_read_request_pdu_bytes(), modbus_read_response_pdu_bytes(out.size()),
        [&](modbus_t* ctx) { return modbus_read_registers(ctx, address, n, out.data()); });
}

void ModbusClient::write_register(std::uint16_t address, std::uint16_t value) {
    const std::string what = "FC6 write register " + std::to_string(address);
    if (impl_->broadcast()) {
        std::uint8_t raw[] = {0,
                              0x06,
                              static_cast<std::uint8_t>(address >> 8),
                              static_cast<std::uint8_t>(address & 0xFF),
                              static_cast<std::uint8_t>(value >> 8),
                              static_cast<std::uint8_t>(value & 0xFF)};
        impl_->send_broadcast(what, raw, sizeof raw);
        return;
    }
    impl_->transact(what, modbus_write_single_pdu_bytes(), modbus_write_single_pdu_bytes(),
                    [&](modbus_t* ctx) { return modbus_write_register(ctx, address, value); });
}

void ModbusClient::write_registers(std::uint16_t address, std::span<const std::uint16_t> values) {
    check_count("write_registers", values.size(), 123);
    check_range("write_registers", address, values.size());
    const int n = static_cast<int>(values.size());
    const std::string what =
        "FC16 write registers " + std::to_string(address) + " x" + std::to_string(n);
    if (impl_->broadcast()) {
        std::uint8_t raw[7 + 2 * 123] = {0,
                                         0x10,
                                         static_cast<std::uint8_t>(address >> 8),
                                         static_cast<std::uint8_t>(address & 0xFF),
                                         0,
                                         static_cast<std::uint8_t>(n),
                                         static_cast<std::uint8_t>(2 * n)};
        for (int i = 0; i < n; ++i) {
            raw[7 + 2 * i] = static_cast<std::uint8_t>(values[static_cast<std::size_t>(i)] >> 8);
            raw[8 + 2 * i] = static_cast<std::uint8_t>(values[static_cast<std::size_t>(i)] & 0xFF);
        }
        impl_->send_broadcast(what, raw, 7 + 2 * n);
        return;
    }
    impl_->transact(what, modbus_write_multiple_request_pdu_bytes(values.size()),
                    modbus_write_multiple_response_pdu_bytes(), [&](modbus_t* ctx) {
                        return modbus_write_registers(ctx, address, n, values.data());
                    });
}

void ModbusClient::write_coil(std::uint16_t address, bool on) {
    impl_->refuse_broadcast("write_coil");
    impl_->transact("FC5 write coil " + std::to_string(address) + (on ? " on" : " off"),
                    modbus_write_single_pdu_bytes(), modbus_write_single_pdu_bytes(),
                    [&](modbus_t* ctx) { return modbus_write_bit(ctx, address, on ? 1 : 0); });
}

void ModbusClient::write_coils(std::uint16_t address, std::span<const std::uint8_t> values) {
    if (values.empty() || values.size() > 1968) {
        throw std::invalid_argument("write_coils: " + std::to_string(values.size()) +
                                    " coils is not in 1..1968");
    }
    if (address + values.size() > 0x10000u) {
        throw std::invalid_argument("write_coils: coils " + std::to_string(address) + ".." +
                                    std::to_string(address + values.size() - 1) +
                                    " run past 65535");
    }
    impl_->refuse_broadcast("write_coils");
    const int n = static_cast<int>(values.size());
    // libmodbus takes one byte per coil (0 off, anything else on) and packs them itself.
    std::uint8_t bits[1968];
    for (std::size_t k = 0; k < values.size(); ++k) bits[k] = values[k] != 0 ? 1 : 0;
    impl_->transact("FC15 write coils " + std::to_string(address) + " x" + std::to_string(n),
                    modbus_write_coils_request_pdu_bytes(values.size()),
                    modbus_write_multiple_response_pdu_bytes(),
                    [&](modbus_t* ctx) { return modbus_write_bits(ctx, address, n, bits); });
}

void ModbusClient::write_read_registers(std::uint16_t write_address,
                                        std::span<const std::uint16_t> values,
                                        std::uint16_t read_address, std::span<std::uint16_t> out) {
    check_count("write_read_registers (write)", values.size(), 121);
    check_count("write_read_registers (read)", out.size(), 125);
    check_range("write_read_registers (write)", write_address, values.size());
    check_range("write_read_registers (read)", read_address, out.size());
    impl_->refuse_broadcast("write_read_registers");
    const int nw = static_cast<int>(values.size());
    const int nr = static_cast<int>(out.size());
    impl_->transact("FC23 write " + std::to_string(write_address) + " x" + std::to_string(nw) +
                        ", read " + std::to_string(read_address) + " x" + std::to_string(nr),
                    modbus_write_read_request_pdu_bytes(values.size()),
                    modbus_read_response_pdu_bytes(out.size()), [&](modbus_t* ctx) {
                        return modbus_write_and_read_registers(
                            ctx, write_address, nw, values.data(), read_address, nr, out.data());
                    });
}

void ModbusClient::reconnect() {
    impl_->disconnect();
    impl_->connect(impl_->name);
}

void ModbusClient::close() {
    impl_->disconnect();
}
bool ModbusClient::connected() const {
    return impl_->open;
}
const ModbusTarget& ModbusClient::target() const {
    return impl_->target;
}
const ModbusClientOptions& ModbusClient::options() const {
    return impl_->options;
}
const ModbusClientCounters& ModbusClient::counters() const {
    return impl_->counters;
}

}  // namespace pathstream::hal
