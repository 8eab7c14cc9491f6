// Size and seed of the seeded property tests, shared by every core test file.
#pragma once

#include <catch2/catch.hpp>
#include <cstdint>

namespace pathstream::test {

/// Random spans per basis (--spans N on the command line).
extern std::uint64_t g_spans_per_basis;

/// The run's seed: Catch2's --rng-seed when given, else a fixed default so runs repeat.
inline std::uint64_t property_seed() {
    const auto seed = Catch::rngSeed();
    return seed != 0 ? seed : 20261122u;
}

}  // namespace pathstream::test
