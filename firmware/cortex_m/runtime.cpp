// The four functions GCC may call even in freestanding code (GCC manual, "C Language"
// standards: memcpy, memmove, memset and memcmp must be provided by the environment). The
// core needs memset (zero-initialised spans and cubics) and memcpy (struct copies). No C
// library is linked, so the images get these small versions. Compiled with -fno-builtin and
// -fno-tree-loop-distribute-patterns so that GCC does not turn the loops back into calls.
#include <cstddef>
#include <cstdint>

namespace {

bool word_aligned(const void* a, const void* b, std::size_t n) {
    return ((reinterpret_cast<std::uintptr_t>(a) | reinterpret_cast<std::uintptr_t>(b) | n) & 3u) ==
           0;
}

}  // namespace

extern "C" {

void* memset(void* dst, int value, std::size_t n) {
    auto* d = static_cast<unsigned char*>(dst);
    const auto byte = static_cast<unsigned char>(value);
    if (word_aligned(dst, dst, n)) {
        const std::uint32_t word = 0x01010101u * byte;
        auto* w = reinterpret_cast<std::uint32_t*>(d);
        for (std::size_t i = 0; i < n / 4; ++i) w[i] = word;
        return dst;
    }
    for (std::size_t i = 0; i < n; ++i) d[i] = byte;
    return dst;
}

void* memcpy(void* __restrict dst, const void* __restrict src, std::size_t n) {
    if (word_aligned(dst, src, n)) {
        auto* d = static_cast<std::uint32_t*>(dst);
        const auto* s = static_cast<const std::uint32_t*>(src);
        for (std::size_t i = 0; i < n / 4; ++i) d[i] = s[i];
        return dst;
    }
    auto* d = static_cast<unsigned char*>(dst);
    const auto* s = static_cast<const unsigned char*>(src);
    for (std::size_t i = 0; i < n; ++i) d[i] = s[i];
    return dst;
}

void* memmove(void* dst, const void* src, std::size_t n) {
    auto* d = static_cast<unsigned char*>(dst);
    const auto* s = static_cast<const unsigned char*>(src);
    if (d < s) {
        for (std::size_t i = 0; i < n; ++i) d[i] = s[i];
    } else {
        for (std::size_t i = n; i > 0; --i) d[i - 1] = s[i - 1];
    }
    return dst;
}

int memcmp(const void* a, const void* b, std::size_t n) {
    const auto* x = static_cast<const unsigned char*>(a);
    const auto* y = static_cast<const unsigned char*>(b);
    for (std::size_t i = 0; i < n; ++i) {
        if (x[i] != y[i]) return x[i] < y[i] ? -1 : 1;
    }
    return 0;
}

}  // extern "C"
