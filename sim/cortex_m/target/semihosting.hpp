// Arm semihosting for the bare-metal images: text output and exit, nothing else.
//
// A semihosting call is `bkpt 0xab` (Thumb) with the operation in r0 and its argument in r1;
// qemu-system-arm handles it when started with -semihosting-config enable=on,target=native.
// Operations used:
//   SYS_WRITE0 (0x04): r1 points to a NUL-terminated string; qemu writes it to stderr.
//   SYS_EXIT   (0x18): on 32-bit Arm r1 holds the reason code itself (not a pointer to a
//                      parameter block as on AArch64). ADP_Stopped_ApplicationExit (0x20026)
//                      makes qemu exit with status 0; any other reason exits with status 1.
// Freestanding: no libc, no heap; the formatting helpers write into caller-provided buffers.
#pragma once

#include <cstdint>

namespace cortex_m {

inline constexpr std::uint32_t kSysWrite0 = 0x04;
inline constexpr std::uint32_t kSysExit = 0x18;
inline constexpr std::uint32_t kAdpStoppedApplicationExit = 0x20026;
inline constexpr std::uint32_t kAdpStoppedRunTimeErrorUnknown = 0x20023;

inline std::uint32_t semihost(std::uint32_t op, const void* arg) {
    register std::uint32_t r0 asm("r0") = op;
    register const void* r1 asm("r1") = arg;
    asm volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

/// Writes a NUL-terminated string to the host's stderr.
inline void write(const char* s) {
    (void)semihost(kSysWrite0, s);
}

/// Ends the emulation: status 0 for success, 1 for anything else (the 32-bit SYS_EXIT cannot
/// carry a status code, only "application exit" or an error reason).
[[noreturn]] inline void exit(bool success) {
    const std::uint32_t reason =
        success ? kAdpStoppedApplicationExit : kAdpStoppedRunTimeErrorUnknown;
    register std::uint32_t r0 asm("r0") = kSysExit;
    register std::uint32_t r1 asm("r1") = reason;
    asm volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    for (;;) {
    }
}

/// A line being assembled on the stack, then written in one semihosting call.
class Line {
public:
    Line& text(const char* s) {
        while (*s != '\0') put(*s++);
        return *this;
    }
    Line& dec(std::uint64_t v) {
        char digits[24];
        int count = 0;
        do {
            digits[count++] = static_cast<char>('0' + static_cast<int>(v % 10u));
            v /= 10u;
        } while (v != 0);
        while (count > 0) put(digits[--count]);
        return *this;
    }
    Line& sdec(std::int64_t v) {
        if (v < 0) {
            put('-');
            return dec(0 - static_cast<std::uint64_t>(v));
        }
        return dec(static_cast<std::uint64_t>(v));
    }
    Line& hex(std::uint64_t v, int digits = 16) {
        for (int i = digits - 1; i >= 0; --i) {
            const unsigned nibble = static_cast<unsigned>(v >> (4 * i)) & 0xFu;
            put(static_cast<char>(nibble < 10 ? '0' + nibble : 'a' + nibble - 10));
        }
        return *this;
    }
    /// Appends a newline and writes the line.
    void end() {
        put('\n');
        buffer_[length_] = '\0';
        write(buffer_);
        length_ = 0;
    }

private:
    void put(char c) {
        if (length_ < sizeof(buffer_) - 2) buffer_[length_++] = c;
    }
    char buffer_[160];
    unsigned length_ = 0;
};

}  // namespace cortex_m
