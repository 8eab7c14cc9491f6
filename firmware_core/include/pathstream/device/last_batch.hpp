// The last batch a device queued, kept by the transport layer so that a resend can be told
// from a different batch under the same sequence numbers: the core acknowledges a resend of
// its last batch by sequence numbers alone.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pathstream::device {

/// A copy of the last queued batch's payload (at most `Bytes`). Task context (the transport
/// that feeds accept_batch). No allocation: `Bytes` + 8 bytes inline.
template <std::size_t Bytes>
class LastBatch {
public:
    /// True when (first, count) is the remembered batch, still the last the device accepted
    /// (`last_accepted` = MotionDevice::last_accepted_sequence()), but `payload` differs from
    /// it: a master out of step, to be refused (kBadSequence). O(length).
    bool conflicts(std::uint32_t first, std::uint16_t count, const std::uint8_t* payload,
                   std::size_t length, std::uint32_t last_accepted) const {
        if (count_ == 0 || first != first_ || count != count_ ||
            last_accepted != first + count - 1u)
            return false;
        if (length != length_) return true;
        for (std::size_t i = 0; i < length; ++i) {
            if (payload[i] != payload_[i]) return true;
        }
        return false;
    }

    /// Keeps a batch the device just queued (not one it acknowledged as a duplicate).
    /// `length` <= Bytes (a longer one is forgotten: nothing is compared). O(length).
    void remember(std::uint32_t first, std::uint16_t count, const std::uint8_t* payload,
                  std::size_t length) {
        if (length > Bytes) {
            count_ = 0;
            return;
        }
        first_ = first;
        count_ = count;
        length_ = static_cast<std::uint16_t>(length);
        for (std::size_t i = 0; i < length; ++i) payload_[i] = payload[i];
    }

private:
    std::uint8_t payload_[Bytes] = {};
    std::uint32_t first_ = 0;
    std::uint16_t count_ = 0;  // 0: nothing remembered
    std::uint16_t length_ = 0;
};

}  // namespace pathstream::device
