// The image's GPIO: pin modes at init, then single BSRR writes (atomic set and reset, so an
// interrupt and the task never read-modify-write the same port) and IDR reads. The qemu model
// has no GPIO: its writes are ignored and its reads return 0.
#pragma once

#include <cstdint>

#include "board.hpp"
#include "registers.hpp"

namespace firmware::pins {

inline volatile std::uint32_t& reg(std::uintptr_t port, std::uint32_t offset) {
    return *reinterpret_cast<volatile std::uint32_t*>(port + offset);
}

/// Sets pin `n` of `port` to `mode` (input, output, alternate) with `af` and `pull`. Init.
inline void configure(std::uintptr_t port, unsigned n, std::uint32_t mode, std::uint32_t af = 0,
                      std::uint32_t pull = 0) {
    volatile std::uint32_t& moder = reg(port, 0x00);
    moder = (moder & ~(3u << (2 * n))) | (mode << (2 * n));
    volatile std::uint32_t& speed = reg(port, 0x08);
    speed = speed | (2u << (2 * n));  // fast: clean step edges
    volatile std::uint32_t& pupd = reg(port, 0x0C);
    pupd = (pupd & ~(3u << (2 * n))) | (pull << (2 * n));
    volatile std::uint32_t& afr = reg(port, n < 8 ? 0x20u : 0x24u);
    const unsigned shift = 4 * (n % 8);
    afr = (afr & ~(15u << shift)) | (af << shift);
}

/// Raises the pins of `set_mask` and lowers those of `reset_mask` on `port` in one write.
inline void write(std::uintptr_t port, std::uint32_t set_mask, std::uint32_t reset_mask) {
    reg(port, 0x18) = (set_mask & 0xFFFFu) | ((reset_mask & 0xFFFFu) << 16);
}

inline void drive(board::Pin p, bool high) {
    write(p.port, high ? 1u << p.number : 0u, high ? 0u : 1u << p.number);
}

inline bool level(board::Pin p) {
    return ((reg(p.port, 0x10) >> p.number) & 1u) != 0;
}

}  // namespace firmware::pins
