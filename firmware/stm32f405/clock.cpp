#include "clock.hpp"

#include <cstdint>

#include "board.hpp"
#include "registers.hpp"

namespace firmware {
namespace {

// Polls `ready` for a bounded time: a clock that never comes up must not hang the reset.
template <typename Ready>
bool wait_for(Ready ready) {
    for (std::uint32_t i = 0; i < 500000u; ++i) {
        if (ready()) return true;
    }
    return false;
}

}  // namespace

void clock_init() {
    using namespace stm32;
    RccAhb1Enr::set_bits(kRccAhb1GpioA | kRccAhb1GpioD | kRccAhb1GpioE);
    RccApb1Enr::set_bits(kRccApb1Tim2 | kRccApb1Tim5 | kRccApb1Usart2);
    RccApb2Enr::set_bits(kRccApb2Usart1);
    if constexpr (board::kQemu) return;
#ifndef PATHSTREAM_FW_QEMU
    // 5 wait states at 168 MHz and 2.7-3.6 V (RM0090 table 10), with prefetch and caches.
    FlashAcr::write(5u | kFlashAcrPrefetch | kFlashAcrICache | kFlashAcrDCache);
    RccCr::set_bits(kRccCrHseOn);
    const bool hse = wait_for([] { return (RccCr::read() & kRccCrHseRdy) != 0; });
    // PLL input 1 MHz (M = source MHz), VCO 336 MHz (N), core /2 (P), USB /7 (Q).
    const std::uint32_t m = hse ? board::kHseHz / 1000000u : 16u;
    RccPllCfgr::write(m | (336u << 6) | (0u << 16) | ((hse ? 1u : 0u) << 22) | (7u << 24));
    // AHB /1, APB1 /4 (42 MHz), APB2 /2 (84 MHz).
    RccCfgr::write((5u << 10) | (4u << 13));
    RccCr::set_bits(kRccCrPllOn);
    if (!wait_for([] { return (RccCr::read() & kRccCrPllRdy) != 0; })) return;
    RccCfgr::set_bits(kRccCfgrSwPll);
    (void)wait_for([] { return (RccCfgr::read() & kRccCfgrSwsMask) == kRccCfgrSwsPll; });
#endif
}

}  // namespace firmware
