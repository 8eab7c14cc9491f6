// A USART driven by polling for transmit and, for the Modbus line, an interrupt per received
// byte. The qemu model ignores BRR, keeps TXE set, and never raises the transmit interrupts,
// which is why transmit is polled on every board.
#pragma once

#include <cstddef>
#include <cstdint>

#include "registers.hpp"

namespace firmware {

template <std::uintptr_t Base>
struct UsartPort {
    using Regs = stm32::Usart<Base>;

    /// 8E1 (`even_parity`: the Modbus serial line's default) or 8N1 at `baud` from a peripheral
    /// clock of `clock_hz` (oversampling by 16: BRR is the rounded clock / baud); the receive
    /// interrupt when `rx_interrupt`. Init context.
    static void init(std::uint32_t clock_hz, std::uint32_t baud, bool even_parity,
                     bool rx_interrupt) {
        Regs::Brr::write((clock_hz + baud / 2u) / baud);
        std::uint32_t cr1 = stm32::kUsartCr1Ue | stm32::kUsartCr1Te | stm32::kUsartCr1Re;
        // Parity takes the word's ninth bit: M selects 9 bits, PCE turns parity on (even).
        if (even_parity) cr1 |= stm32::kUsartCr1M | stm32::kUsartCr1Pce;
        if (rx_interrupt) cr1 |= stm32::kUsartCr1Rxneie;
        Regs::Cr1::write(cr1);
    }

    /// Sends `n` bytes, waiting for room before each. Task context.
    static void write(const std::uint8_t* bytes, std::size_t n) {
        for (std::size_t i = 0; i < n; ++i) {
            while ((Regs::Sr::read() & stm32::kUsartSrTxe) == 0) {
            }
            Regs::Dr::write(bytes[i]);
        }
    }

    /// Takes the received byte, if any (reading SR then DR also clears an overrun). The
    /// receive interrupt's work; `overrun` is set when a byte was lost before this one.
    static bool read(std::uint8_t& byte, bool& overrun) {
        const std::uint32_t sr = Regs::Sr::read();
        overrun = (sr & stm32::kUsartSrOre) != 0;
        // A byte with a parity or framing error is read (to clear it) and dropped: the frame's
        // CRC then fails and the master asks again.
        if ((sr & (stm32::kUsartSrRxne | stm32::kUsartSrOre)) == 0) return false;
        byte = static_cast<std::uint8_t>(Regs::Dr::read() & 0xFFu);
        return (sr & stm32::kUsartSrRxne) != 0 &&
               (sr & (stm32::kUsartSrPe | stm32::kUsartSrFe)) == 0;
    }
};

}  // namespace firmware
