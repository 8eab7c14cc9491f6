// Private to the server: gathers one Modbus TCP request (MBAP header + PDU) from a
// connection's bytes as they trickle in, so no connection ever makes the server wait.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace pathstream::hal::detail {

/// One connection's frame in progress. Reads are sized by wanted(), so the buffer never holds
/// more than one frame: bytes of a pipelined next request stay in the socket until this one
/// is served. No allocation; O(1) per call.
class MbapAssembler {
public:
    static constexpr std::size_t kHeaderBytes = 7;      ///< transaction, protocol, length, unit
    static constexpr std::size_t kMaxFrameBytes = 260;  ///< MODBUS_TCP_MAX_ADU_LENGTH

    enum class State : std::uint8_t {
        kPartial,   ///< more bytes needed
        kComplete,  ///< frame() holds one whole request
        kBad,       ///< protocol id not 0 or a length no request has: drop the connection
    };

    /// Bytes to read next (to the end of the header, then of the frame); 0 when complete.
    std::size_t wanted() const {
        if (filled_ < kHeaderBytes) return kHeaderBytes - filled_;
        return frame_bytes() - filled_;
    }
    /// Where the next wanted() bytes go.
    std::uint8_t* write_pointer() { return buffer_.data() + filled_; }

    /// Accounts `n` (<= wanted()) bytes just written at write_pointer().
    State added(std::size_t n) {
        filled_ += n;
        if (filled_ < kHeaderBytes) return State::kPartial;
        const std::size_t length = static_cast<std::size_t>(buffer_[4] << 8 | buffer_[5]);
        // The length counts the unit id and the PDU: a function code at least, 254 at most.
        if (buffer_[2] != 0 || buffer_[3] != 0 || length < 2 || length > kMaxFrameBytes - 6) {
            return State::kBad;
        }
        return filled_ == frame_bytes() ? State::kComplete : State::kPartial;
    }

    bool empty() const { return filled_ == 0; }
    const std::uint8_t* frame() const { return buffer_.data(); }
    std::size_t size() const { return filled_; }
    /// Starts the next frame.
    void clear() { filled_ = 0; }

private:
    std::size_t frame_bytes() const {
        return 6 + static_cast<std::size_t>(buffer_[4] << 8 | buffer_[5]);
    }

    std::array<std::uint8_t, kMaxFrameBytes> buffer_{};
    std::size_t filled_ = 0;
};

}  // namespace pathstream::hal::detail
