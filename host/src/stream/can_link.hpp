// The native CAN transport to one device (docs/can.md): frames of our node, acks, status
// requests and commands, with the link timeout. The streamer and `pathstream ctl` share it.
#pragma once

#include <algorithm>
#include <chrono>
#include <sstream>
#include <string>

#include "pathstream/device/can_protocol.hpp"
#include "pathstream/hal/can_bus.hpp"
#include "pathstream/host/can_stream.hpp"
#include "pathstream/host/device_link.hpp"

namespace pathstream::host {

/// An ack's result byte as text: a core Status name, or the transfer results 128-130.
std::string can_result_name(std::uint8_t result);

namespace pc = device::can;

/// The status frames' values as a bus-neutral snapshot.
DeviceSnapshot snapshot_of(const pc::Status3& s);

class CanLink {
public:
    using Clock = std::chrono::steady_clock;

    /// Talks to node options.node on `bus`; counts frames, bits and timeouts into `counters`.
    /// Throws std::invalid_argument for a node outside 1..127.
    CanLink(hal::CanBus& bus, const CanStreamOptions& options, CanStreamReport& counters);

    [[noreturn]] void fail(const std::string& what) const {
        throw StreamError(options_.name + ": " + what);
    }
    /// Restarts the link-timeout clock (before a first request).
    void mark_alive() { last_heard_ = Clock::now(); }

    /// Sends command `c` until its ack arrives (commands are idempotent); returns the result.
    std::uint8_t command(std::uint8_t c) { return command_frame(pc::encode_command(node_, c), c); }

    /// Sends `frame` (a command, or a command with arguments whose command byte is `c`) until
    /// the command ack for `c` arrives; returns its result. A jog whose ack was lost and
    /// that is sent again is refused (the device is no longer idle): the caller reads the
    /// status to tell.
    std::uint8_t command_frame(const pc::Frame& frame, std::uint8_t c) {
        while (true) {
            send(frame);
            pc::Ack ack;
            if (!wait_ack(pc::kAckCommand, c, ack)) continue;
            return ack.result;
        }
    }

    /// Sends `f`, waiting while the controller's queue is full. Throws StreamError on bus-off.
    void send(const pc::Frame& f) {
        hal::CanFrame h;
        h.id = f.id;
        h.length = f.length;
        std::copy(f.data, f.data + 8, h.data);
        while (true) {
            const hal::CanSendResult r = bus_.send(h);
            if (r == hal::CanSendResult::kQueued) break;
            if (r == hal::CanSendResult::kBusOff)
                fail("the host's CAN controller is bus-off: stopping");
            if (r == hal::CanSendResult::kError) fail("the CAN interface refused a frame (down?)");
            // Queue full: let the controller drain; a dead bus shows up as the link timeout.
            check_link();
            hal::CanFrame in;
            if (bus_.receive(in, 200)) take(in);
        }
        ++counters_.frames_sent;
        counters_.bits_sent += pc::frame_bits_worst_case(f.length);
    }

    // Receives one frame from our node within `timeout_us`; false when none came.
    bool next_frame(pc::Frame& out, std::uint32_t timeout_us) {
        const auto deadline = Clock::now() + std::chrono::microseconds(timeout_us);
        while (true) {
            const auto left =
                std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now())
                    .count();
            hal::CanFrame in;
            if (!bus_.receive(in, static_cast<std::uint32_t>(std::max<long long>(0, left))))
                return false;
            if (take(in)) {
                out.id = in.id;
                out.length = in.length;
                std::copy(in.data, in.data + 8, out.data);
                return true;
            }
            if (Clock::now() >= deadline) return false;
        }
    }

    // True for a device -> host frame of our node (counted, and the link is alive).
    bool take(const hal::CanFrame& in) {
        if (in.extended || in.remote || pc::node_of(in.id) != node_) return false;
        const std::uint32_t f = pc::function_of(in.id);
        if (f != pc::kAckBase && f != pc::kStatusABase && f != pc::kStatusBBase &&
            f != pc::kStatusCBase && f != pc::kStatusDBase && f != pc::kStatusEBase) {
            return false;
        }
        ++counters_.frames_received;
        counters_.bits_received += pc::frame_bits_worst_case(in.length);
        last_heard_ = Clock::now();
        return true;
    }

    /// Throws StreamError when our controller is bus-off or the device has been silent too long.
    void check_link() const {
        const double silent = std::chrono::duration<double>(Clock::now() - last_heard_).count();
        if (bus_.state() == hal::CanBusState::kBusOff)
            fail("the host's CAN controller is bus-off: stopping");
        if (silent > options_.link_timeout_seconds) {
            std::ostringstream m;
            m << "no answer from node " << unsigned(node_) << " for " << std::fixed;
            m.precision(1);
            m << silent
              << " s (device off the bus, bus-off, or not there): stopping; a device that was "
                 "running holds by itself";
            fail(m.str());
        }
    }

    std::uint32_t ack_timeout_us() const { return options_.ack_timeout_ms * 1000u; }

    // Waits for an ack of `kind` for `sequence`; false on timeout.
    bool wait_ack(std::uint8_t kind, std::uint32_t sequence, pc::Ack& ack) {
        const auto deadline = Clock::now() + std::chrono::microseconds(ack_timeout_us());
        while (Clock::now() < deadline) {
            pc::Frame f;
            const auto left =
                std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now())
                    .count();
            if (!next_frame(f, static_cast<std::uint32_t>(std::max<long long>(0, left)))) break;
            if (pc::function_of(f.id) != pc::kAckBase || !pc::decode_ack(f, ack)) continue;
            if (ack.kind == kind && ack.sequence == sequence)
                return true;  // stale acks are ignored
        }
        ++counters_.timeouts;
        check_link();
        return false;
    }

    // ---- protocol steps ------------------------------------------------------------------

    /// Asks for the status until all its frames arrive (A to D, E per axis) within one timeout.
    pc::Status3 request_status() {
        while (true) {
            send(pc::encode_command(node_, pc::kCommandStatusRequest));
            ++counters_.status_requests;
            pc::Status3 s;
            unsigned seen = 0;
            const auto deadline = Clock::now() + std::chrono::microseconds(ack_timeout_us());
            // A to D, then E for each of the device's axes (bit 4 + axis; StatusA names the count).
            const auto complete = [&] {
                const unsigned axes = std::min<unsigned>(s.axes, kMaxAxes);
                return (seen & 1u) != 0 &&
                       seen == (((1u << pc::kStatusFrames) - 1u) | (((1u << axes) - 1u) << 4));
            };
            while (!complete() && Clock::now() < deadline) {
                pc::Frame f;
                const auto left =
                    std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now())
                        .count();
                if (!next_frame(f, static_cast<std::uint32_t>(std::max<long long>(0, left)))) break;
                const std::uint32_t fn = pc::function_of(f.id);
                if (pc::decode_status_part(f, s)) {
                    seen |= fn == pc::kStatusABase   ? 1u
                            : fn == pc::kStatusBBase ? 2u
                            : fn == pc::kStatusCBase ? 4u
                            : fn == pc::kStatusDBase ? 8u
                                                     : 16u << f.data[0];
                }
            }
            if (complete()) return s;
            ++counters_.timeouts;
            check_link();
        }
    }

private:
    hal::CanBus& bus_;
    const CanStreamOptions& options_;
    std::uint8_t node_;
    CanStreamReport& counters_;
    Clock::time_point last_heard_ = Clock::now();
};

}  // namespace pathstream::host
