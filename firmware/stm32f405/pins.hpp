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

/// One output pin as a hal::OutputLine: set(true) asserts it at the board's polarity.
struct Output {
    board::Pin pin;
    bool active_low;
    void set(bool active) const { drive(pin, active != active_low); }
};

/// One input pin as a hal::InputLevel: active() after the board's polarity.
struct Input {
    board::Pin pin;
    bool active_low;
    bool active() const { return level(pin) != active_low; }
};

/// Every axis's step and direction pins, on one port, as hal::StepDirLines: each call is one
/// BSRR write, so the steps of a group rise together.
template <unsigned Axes>
struct StepDirPins {
    static std::uint32_t step_pins(std::uint32_t axes) {
        std::uint32_t mask = 0;
        for (unsigned a = 0; a < Axes; ++a)
            if (((axes >> a) & 1u) != 0) mask |= 1u << board::kStepPin[a];
        return mask;
    }
    void set_directions(std::uint32_t forward) const {
        std::uint32_t up = 0, down = 0;
        for (unsigned a = 0; a < Axes; ++a) {
            if (((forward >> a) & 1u) != 0) {
                up |= 1u << board::kDirPin[a];
            } else {
                down |= 1u << board::kDirPin[a];
            }
        }
        write(board::kStepDirPort, up, down);
    }
    void raise_steps(std::uint32_t axes) const { write(board::kStepDirPort, step_pins(axes), 0); }
    void lower_steps(std::uint32_t axes) const { write(board::kStepDirPort, 0, step_pins(axes)); }
};

}  // namespace firmware::pins
