// The fingerprint the device keeps of the last batch it queued, so that a resend under the
// same sequence numbers can be told from a different batch without keeping its bytes.
#pragma once

#include <cstddef>
#include <cstdint>

namespace pathstream::device {

/// CRC-32 (IEEE 802.3: reflected polynomial 0xEDB88320, initial and final 0xFFFFFFFF) of
/// bytes[0..length). Any two batches that differ in 1 to 3 bits, or in one burst of up to 32
/// bits, get different values. Bitwise, no table: ~8 shift/xor steps per byte (a 1,792-byte
/// batch in ~15,000 steps), no storage. Any context.
std::uint32_t batch_crc32(const std::uint8_t* bytes, std::size_t length);

}  // namespace pathstream::device
