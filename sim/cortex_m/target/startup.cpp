// Minimal Cortex-M startup shared by every image: vector table, reset handler, fault handler.
//
// The reset handler copies .data from its load address, zeroes .bss, runs the static
// constructors (.preinit_array, .init_array), calls main() and reports its result through
// semihosting SYS_EXIT. No C library, no heap, no atexit: destructors of statics never run.
// Works on ARMv6-M (Cortex-M0/M0+) and ARMv7-M (Cortex-M3/M4): only word loads and stores.
#include <cstdint>

#include "memory_init.hpp"
#include "semihosting.hpp"

extern "C" {
// From the linker scripts (mps2-an386.ld, microbit.ld).
extern std::uint32_t __stack_top[];

int main();
[[noreturn]] void reset_handler();
[[noreturn]] void fault_handler();
}

extern "C" [[noreturn]] void reset_handler() {
    cortex_m::init_memory();
    const int status = main();
    cortex_m::exit(status == 0);
}

extern "C" [[noreturn]] void fault_handler() {
    // Any fault (HardFault, and on v7-M MemManage/BusFault/UsageFault) ends the run as failed,
    // so that a broken image fails its test instead of hanging until the timeout.
    cortex_m::write("FAULT: processor exception, stopping\n");
    cortex_m::exit(false);
}

// The first 16 entries of the vector table: initial stack pointer, then the system
// exceptions. No peripheral interrupt is enabled by any image, so none is listed.
using Vector = void (*)();
extern "C" [[gnu::section(".vectors"), gnu::used]] const Vector g_vector_table[16] = {
    reinterpret_cast<Vector>(__stack_top),  // 0: initial MSP
    reset_handler,                          // 1: Reset
    fault_handler,                          // 2: NMI
    fault_handler,                          // 3: HardFault
    fault_handler,                          // 4: MemManage (v7-M)
    fault_handler,                          // 5: BusFault (v7-M)
    fault_handler,                          // 6: UsageFault (v7-M)
    nullptr,
    nullptr,
    nullptr,
    nullptr,        // 7-10: reserved
    fault_handler,  // 11: SVCall
    fault_handler,  // 12: DebugMonitor (v7-M)
    nullptr,        // 13: reserved
    fault_handler,  // 14: PendSV
    fault_handler,  // 15: SysTick
};
