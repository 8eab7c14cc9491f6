// Bare-metal image: runs the shared workload (workload/workload.hpp) and prints its summary
// and checksum through semihosting. ctest compares the checksum with the host build's.
// It first checks its own startup: .data copied from its load address, .bss zeroed, static
// constructors run (startup.cpp).
#include <cstdint>

#include "semihosting.hpp"
#include "workload.hpp"

namespace {

volatile std::uint32_t g_ctor_source = 0x600dc70u;  // .data; read at run time by the ctor

struct StartupProbe {
    std::uint32_t value;
    StartupProbe() : value(g_ctor_source) {}  // a volatile read: cannot be constant-folded
};

StartupProbe g_probe;                              // dynamic initialisation via .init_array
volatile std::uint32_t g_data_word = 0x12345678u;  // .data (volatile: not folded to a constant)
volatile std::uint32_t g_bss_words[4];             // .bss

bool startup_ok() {
    cortex_m::Line line;
    const bool data = g_data_word == 0x12345678u;
    const bool bss = (g_bss_words[0] | g_bss_words[1] | g_bss_words[2] | g_bss_words[3]) == 0;
    const bool ctors = g_probe.value == 0x600dc70u;
    line.text("startup data=")
        .text(data ? "ok" : "BAD")
        .text(" bss=")
        .text(bss ? "ok" : "BAD")
        .text(" ctors=")
        .text(ctors ? "ok" : "BAD")
        .end();
    return data && bss && ctors;
}

}  // namespace

int main() {
    if (!startup_ok()) return 1;
    const pathstream::workload::Summary s = pathstream::workload::run();
    cortex_m::Line line;
    line.text("workload ticks=")
        .dec(s.ticks)
        .text(" accepted=")
        .dec(s.spans_accepted)
        .text(" rejected=")
        .dec(s.spans_rejected)
        .text(" horner=")
        .dec(s.horner_evaluations)
        .text(" mismatches=")
        .dec(s.mismatches)
        .end();
    line.text("checksum=").hex(s.checksum).end();
    return s.mismatches == 0 ? 0 : 1;
}
