// What the one streaming loop (SpanStreamer) needs from a bus: a device's status, its
// configuration, its commands and batches of encoded spans. The Modbus and native CAN links
// implement it; everything a stream decides lives in the streamer, once.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "pathstream/device/device_state.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/stream_types.hpp"
#include "pathstream/machine/device_setup.hpp"

namespace pathstream::host {

/// The bus's answer to one batch of spans.
struct BatchAnswer {
    enum class Kind {
        kAccepted,  ///< the device acknowledged every span of the batch
        kLater,     ///< its queue was fuller than known: nothing taken, send again later
        kRefused,   ///< the device refused the batch; `reason` says why
        kUnknown,   ///< no answer: the status tells whether the device took it
    };
    Kind kind = Kind::kAccepted;
    /// A status read with the answer (Modbus FC23 brings one; a refusal or an unknown answer
    /// reads one), else nullopt: the streamer's last status stands.
    std::optional<DeviceSnapshot> status;
    /// The device's free queue slots after the batch, when the answer carries them.
    std::optional<unsigned> free_slots;
    std::string reason;  ///< kRefused: the device's words, with any hint the bus can add
};

/// One device on one bus, as a stream sees it. Not thread-safe: the streaming thread only.
/// Every call may block for the link timeout; every failure is a StreamError naming the target.
class BusSession {
public:
    virtual ~BusSession() = default;

    /// The target as messages name it (its URL).
    virtual const std::string& target_name() const = 0;
    /// Throws StreamError "TARGET: what".
    [[noreturn]] void fail(const std::string& what) const {
        throw StreamError(target_name() + ": " + what);
    }
    /// Restarts the link-timeout clock (before a stream's first request).
    virtual void mark_alive() = 0;
    /// One fresh status read (retried until the link timeout).
    virtual DeviceSnapshot read_status() = 0;
    /// Fails unless `s` is a device of this protocol and version (magic, version number).
    virtual void check_protocol(const DeviceSnapshot& s) const = 0;
    /// Writes the tick rate, per-axis limits and pen timing; nullopt when the device took
    /// them, else its reason for refusing.
    virtual std::optional<std::string> configure(const DeviceLimitsLsb& limits, unsigned axes) = 0;
    /// Sends command `c`; nullopt when the device took it, else its reason for refusing.
    virtual std::optional<std::string> command(device::Command c) = 0;
    /// Most spans the next batch may carry (a noisy link may lower it as it goes).
    virtual std::size_t batch_span_limit() const = 0;
    /// Most encoded bytes one batch may carry.
    virtual std::size_t batch_byte_limit() const = 0;
    /// Sends `count` encoded spans, `payload`, numbered from `first`, and reports the answer.
    virtual BatchAnswer send_batch(std::uint32_t first, std::size_t count,
                                   const std::vector<std::uint8_t>& payload) = 0;
    /// True when every accepted batch's answer is a fresh status (the streamer can send a batch
    /// instead of a status poll when it expects the lead to have drained).
    virtual bool batch_answers_with_status() const = 0;
    /// Text appended to a refusal: what the device's status says of it ("" when nothing).
    virtual std::string refusal_note(const DeviceSnapshot& s) const = 0;
};

}  // namespace pathstream::host
