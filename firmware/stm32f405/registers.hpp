// The STM32F405/407 registers the image touches, from RM0090 (the reference manual of the
// STM32F405/415/407/417/427/437/429/439): addresses, offsets and bit positions for RCC, FLASH,
// GPIO, USART, the general-purpose timers TIM2-5, and the Cortex-M4's NVIC and SCB. Written
// here for the few peripherals used rather than taken from a vendor SDK.
#pragma once

#include <cstdint>

namespace stm32 {

/// One memory-mapped 32-bit register at `Address`. Every access is a volatile word access.
template <std::uintptr_t Address>
struct Reg {
    static volatile std::uint32_t& ref() {
        return *reinterpret_cast<volatile std::uint32_t*>(Address);
    }
    static std::uint32_t read() { return ref(); }
    static void write(std::uint32_t v) { ref() = v; }
    static void set_bits(std::uint32_t m) { ref() = ref() | m; }
    static void clear_bits(std::uint32_t m) { ref() = ref() & ~m; }
};

// --- RCC (RM0090 section 7.3) ------------------------------------------------------------------
inline constexpr std::uintptr_t kRcc = 0x40023800u;
using RccCr = Reg<kRcc + 0x00>;
using RccPllCfgr = Reg<kRcc + 0x04>;
using RccCfgr = Reg<kRcc + 0x08>;
using RccAhb1Enr = Reg<kRcc + 0x30>;
using RccApb1Enr = Reg<kRcc + 0x40>;
using RccApb2Enr = Reg<kRcc + 0x44>;
inline constexpr std::uint32_t kRccCrHseOn = 1u << 16, kRccCrHseRdy = 1u << 17;
inline constexpr std::uint32_t kRccCrPllOn = 1u << 24, kRccCrPllRdy = 1u << 25;
inline constexpr std::uint32_t kRccCfgrSwPll = 2u << 0, kRccCfgrSwsMask = 3u << 2,
                               kRccCfgrSwsPll = 2u << 2;
inline constexpr std::uint32_t kRccAhb1GpioA = 1u << 0, kRccAhb1GpioD = 1u << 3,
                               kRccAhb1GpioE = 1u << 4;
inline constexpr std::uint32_t kRccApb1Tim2 = 1u << 0, kRccApb1Tim5 = 1u << 3,
                               kRccApb1Usart2 = 1u << 17;
inline constexpr std::uint32_t kRccApb2Usart1 = 1u << 4;

// --- FLASH interface (RM0090 section 3.9) -------------------------------------------------------
using FlashAcr = Reg<0x40023C00u>;
inline constexpr std::uint32_t kFlashAcrPrefetch = 1u << 8, kFlashAcrICache = 1u << 9,
                               kFlashAcrDCache = 1u << 10;

// --- GPIO (RM0090 section 8.4) ------------------------------------------------------------------
inline constexpr std::uintptr_t kGpioA = 0x40020000u, kGpioD = 0x40020C00u, kGpioE = 0x40021000u;
template <std::uintptr_t Port>
struct Gpio {
    using Moder = Reg<Port + 0x00>;
    using Ospeedr = Reg<Port + 0x08>;
    using Pupdr = Reg<Port + 0x0C>;
    using Idr = Reg<Port + 0x10>;
    using Bsrr = Reg<Port + 0x18>;
    using Afrl = Reg<Port + 0x20>;
    using Afrh = Reg<Port + 0x24>;
};
inline constexpr std::uint32_t kModeInput = 0, kModeOutput = 1, kModeAlternate = 2;
inline constexpr std::uint32_t kPullUp = 1;

// --- USART (RM0090 section 30.6) ----------------------------------------------------------------
inline constexpr std::uintptr_t kUsart1 = 0x40011000u, kUsart2 = 0x40004400u;
template <std::uintptr_t Base>
struct Usart {
    using Sr = Reg<Base + 0x00>;
    using Dr = Reg<Base + 0x04>;
    using Brr = Reg<Base + 0x08>;
    using Cr1 = Reg<Base + 0x0C>;
};
inline constexpr std::uint32_t kUsartSrPe = 1u << 0, kUsartSrFe = 1u << 1, kUsartSrOre = 1u << 3,
                               kUsartSrRxne = 1u << 5, kUsartSrTxe = 1u << 7;
inline constexpr std::uint32_t kUsartCr1Re = 1u << 2, kUsartCr1Te = 1u << 3,
                               kUsartCr1Rxneie = 1u << 5, kUsartCr1Pce = 1u << 10,
                               kUsartCr1M = 1u << 12, kUsartCr1Ue = 1u << 13;

// --- TIM2-5 (RM0090 section 18.4) ---------------------------------------------------------------
inline constexpr std::uintptr_t kTim2 = 0x40000000u, kTim5 = 0x40000C00u;
template <std::uintptr_t Base>
struct Timer {
    using Cr1 = Reg<Base + 0x00>;
    using Dier = Reg<Base + 0x0C>;
    using Sr = Reg<Base + 0x10>;
    using Egr = Reg<Base + 0x14>;
    using Cnt = Reg<Base + 0x24>;
    using Psc = Reg<Base + 0x28>;
    using Arr = Reg<Base + 0x2C>;
    using Ccr1 = Reg<Base + 0x34>;
    using Ccr2 = Reg<Base + 0x38>;
};
inline constexpr std::uint32_t kTimCr1Cen = 1u << 0, kTimDierUie = 1u << 0, kTimSrUif = 1u << 0,
                               kTimEgrUg = 1u << 0;
/// Compare channels 1 and 2 (frozen output mode, the reset value: interrupts only).
inline constexpr std::uint32_t kTimDierCc1ie = 1u << 1, kTimDierCc2ie = 1u << 2,
                               kTimSrCc1if = 1u << 1, kTimSrCc2if = 1u << 2;

// --- Interrupt numbers (RM0090 table 61) --------------------------------------------------------
inline constexpr unsigned kIrqTim2 = 28, kIrqTim5 = 50, kIrqUsart1 = 37, kIrqUsart2 = 38;
inline constexpr unsigned kIrqCount = 82;  ///< peripheral vectors of the STM32F405/407

// --- Cortex-M4 system control (ARMv7-M ARM, B3.4 NVIC, B3.2 SCB) --------------------------------
template <unsigned Irq>
inline void nvic_enable() {
    Reg<0xE000E100u + 4u * (Irq / 32u)>::write(1u << (Irq % 32u));
}
/// Priority of an interrupt: the top four bits of its byte are implemented (16 levels), lower
/// numbers preempt higher ones.
template <unsigned Irq>
inline void nvic_priority(std::uint8_t level) {
    *reinterpret_cast<volatile std::uint8_t*>(0xE000E400u + Irq) =
        static_cast<std::uint8_t>(level << 4);
}

inline void enable_interrupts() {
    asm volatile("cpsie i" ::: "memory");
}
inline void disable_interrupts() {
    asm volatile("cpsid i" ::: "memory");
}
inline void wait_for_interrupt() {
    asm volatile("wfi");
}

}  // namespace stm32
