// Little-endian field access in CAN frame data (CANopen is little-endian throughout).
#pragma once

#include <cstdint>

#include "pathstream/hal/can_bus.hpp"

namespace pathstream::host::cia402 {

inline std::uint32_t get_le(const hal::CanFrame& f, unsigned at, unsigned bytes) {
    std::uint32_t v = 0;
    for (unsigned i = 0; i < bytes; ++i) v |= static_cast<std::uint32_t>(f.data[at + i]) << (8 * i);
    return v;
}

inline void put_le(hal::CanFrame& f, unsigned at, unsigned bytes, std::uint32_t v) {
    for (unsigned i = 0; i < bytes; ++i) f.data[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

inline hal::CanFrame make_frame(std::uint32_t id, std::uint8_t length) {
    hal::CanFrame f;
    f.id = id;
    f.length = length;
    return f;
}

}  // namespace pathstream::host::cia402
