// Catch2 entry point for the core tests, with the property-test size as an option:
//   core_tests --spans N   (random spans per basis; default 100000, CI's setting)
//   core_tests --stress-ticks N  (ticks per device stress test; default 1000000, CI's setting)
//   core_tests --rng-seed S  (Catch2's own option; the seed in use is printed)
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "core/property_settings.hpp"

namespace pathstream::test {
std::uint64_t g_spans_per_basis = 100000;
std::uint64_t g_stress_ticks = 1000000;
}  // namespace pathstream::test

int main(int argc, char* argv[]) {
    Catch::Session session;
    std::uint64_t spans = pathstream::test::g_spans_per_basis;
    std::uint64_t stress_ticks = pathstream::test::g_stress_ticks;
    using Catch::clara::Opt;
    session.cli(session.cli() |
                Opt(spans, "count")["--spans"]("random spans per basis in property tests") |
                Opt(stress_ticks, "ticks")["--stress-ticks"]("ticks per device stress test"));
    if (const int rc = session.applyCommandLine(argc, argv); rc != 0) return rc;
    pathstream::test::g_spans_per_basis = spans;
    pathstream::test::g_stress_ticks = stress_ticks;
    return session.run();
}
