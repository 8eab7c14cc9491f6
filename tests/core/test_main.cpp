// Catch2 entry point for the core tests, with the property-test size as an option:
//   core_tests --spans N   (random spans per basis; default 100000, CI's setting)
//   core_tests --rng-seed S  (Catch2's own option; the seed in use is printed)
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "core/property_settings.hpp"

namespace pathstream::test {
std::uint64_t g_spans_per_basis = 100000;
}

int main(int argc, char* argv[]) {
    Catch::Session session;
    std::uint64_t spans = pathstream::test::g_spans_per_basis;
    using Catch::clara::Opt;
    session.cli(session.cli() |
                Opt(spans, "count")["--spans"]("random spans per basis in property tests"));
    if (const int rc = session.applyCommandLine(argc, argv); rc != 0) return rc;
    pathstream::test::g_spans_per_basis = spans;
    return session.run();
}
