// What a bare-metal reset handler does before main(): copy .data from its load address, zero
// .bss, run the static constructors. Shared by every image (the firmware and the qemu proofs of
// the core); the symbols come from each image's linker script. Word loops only, so it runs on
// ARMv6-M and ARMv7-M alike; volatile so that GCC does not turn the loops into calls to
// memcpy/memset before .data and .bss exist.
#pragma once

#include <cstdint>

extern "C" {
extern std::uint32_t __data_load[], __data_start[], __data_end[];
extern std::uint32_t __bss_start[], __bss_end[];
extern void (*__preinit_array_start[])();
extern void (*__preinit_array_end[])();
extern void (*__init_array_start[])();
extern void (*__init_array_end[])();
}

namespace cortex_m {

/// Copies .data, zeroes .bss, runs .preinit_array and .init_array. Reset context, once, before
/// anything reads a static.
inline void init_memory() {
    volatile std::uint32_t* d = __data_start;
    const std::uint32_t* s = __data_load;
    while (d < __data_end) *d++ = *s++;
    for (volatile std::uint32_t* b = __bss_start; b < __bss_end;) *b++ = 0;
    for (auto f = __preinit_array_start; f != __preinit_array_end; ++f) (*f)();
    for (auto f = __init_array_start; f != __init_array_end; ++f) (*f)();
}

}  // namespace cortex_m
