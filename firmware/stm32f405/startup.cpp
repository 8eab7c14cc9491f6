// Reset, the vector table and the painted stack of the STM32F405 image. The reset handler
// paints the stack below its own frame (for the high-water figure), sets up memory and calls
// main(), which never returns. Unused interrupts and every fault land in one handler that
// stops the machine: step outputs stop with the CPU, and the drives' enable is dropped.
#include <cstdint>

#include "board.hpp"
#include "firmware.hpp"
#include "memory_init.hpp"
#include "registers.hpp"

extern "C" {
extern std::uint32_t __stack_top[];
extern std::uint32_t __stack_limit[];

int main();
[[noreturn]] void reset_handler();
[[noreturn]] void fault_handler();
}

namespace {

constexpr std::uint32_t kPaint = 0xC0FFEE55u;

// Paints from the stack's limit up to a little below the current stack pointer: whatever is
// still painted later was never used. Reset context, before anything else runs.
[[gnu::always_inline]] inline void paint_stack() {
    std::uint32_t* sp;
    asm volatile("mov %0, sp" : "=r"(sp));
    for (volatile std::uint32_t* p = __stack_limit; p < sp - 16;) *p++ = kPaint;
}

}  // namespace

namespace firmware {

std::uint32_t stack_bytes_used() {
    const std::uint32_t* p = __stack_limit;
    while (p < __stack_top && *p == kPaint) ++p;
    return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(__stack_top) -
                                      reinterpret_cast<std::uintptr_t>(p));
}

std::uint32_t stack_bytes_total() {
    return static_cast<std::uint32_t>(reinterpret_cast<std::uintptr_t>(__stack_top) -
                                      reinterpret_cast<std::uintptr_t>(__stack_limit));
}

}  // namespace firmware

extern "C" [[noreturn]] void reset_handler() {
    paint_stack();
    cortex_m::init_memory();
    main();
    fault_handler();
}

extern "C" [[noreturn]] void fault_handler() {
    stm32::disable_interrupts();
    firmware::halt_outputs();
    for (;;) stm32::wait_for_interrupt();
}

extern "C" void tim5_irq();
extern "C" void usart1_irq();
extern "C" void tim2_irq();

using Vector = void (*)();

// The table: the initial stack pointer, 15 system entries, then the STM32F405's 82 peripheral
// interrupts. Only the tick (TIM5), the Modbus receiver (USART1) and the step pulses (TIM2)
// are used. Constant-initialised (an address and a constexpr array), so it is in flash.
struct Handlers {
    Vector entries[15 + stm32::kIrqCount];
};
struct VectorTable {
    std::uint32_t* initial_sp;
    Handlers handlers;
};

constexpr Handlers make_handlers() {
    Handlers h{};
    // entries[k] is exception k + 1: 1 Reset, 2 NMI, 3 HardFault, ..., 16 + n IRQ n.
    for (auto& e : h.entries) e = fault_handler;
    h.entries[0] = reset_handler;
    constexpr unsigned kReserved[] = {7, 8, 9, 10, 13};
    for (unsigned k : kReserved) h.entries[k - 1] = nullptr;
    h.entries[15 + stm32::kIrqTim5] = tim5_irq;
    h.entries[15 + stm32::kIrqUsart1] = usart1_irq;
    h.entries[15 + stm32::kIrqTim2] = tim2_irq;
    return h;
}

extern "C" [[gnu::section(".vectors"), gnu::used]] const VectorTable g_vector_table = {
    __stack_top, make_handlers()};
