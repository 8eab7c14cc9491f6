// Int128 (the core's portable two-word integer) against the compiler's __int128.
#include <catch2/catch.hpp>
#include <random>

#include "core/property_settings.hpp"
#include "pathstream/wide_int.hpp"

using pathstream::Int128;
using i128 = __int128;

namespace {

i128 native(Int128 v) {
    return static_cast<i128>((static_cast<unsigned __int128>(v.hi) << 64) | v.lo);
}
Int128 portable(i128 v) {
    const auto u = static_cast<unsigned __int128>(v);
    return Int128{static_cast<std::uint64_t>(u), static_cast<std::uint64_t>(u >> 64)};
}

/// Random value with a random magnitude (1..126 bits) and sign.
i128 random_value(std::mt19937_64& rng) {
    const int bits = 1 + static_cast<int>(rng() % 126);
    unsigned __int128 v = (static_cast<unsigned __int128>(rng()) << 64) | rng();
    v &= (static_cast<unsigned __int128>(1) << bits) - 1;
    return rng() % 2 ? -static_cast<i128>(v) : static_cast<i128>(v);
}

}  // namespace

TEST_CASE("Int128 add, subtract, negate and compare agree with __int128", "[int128]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    std::mt19937_64 rng(seed);
    for (int i = 0; i < 200000; ++i) {
        const i128 a = random_value(rng) / 2, b = random_value(rng) / 2;
        REQUIRE(native(portable(a) + portable(b)) == a + b);
        REQUIRE(native(portable(a) - portable(b)) == a - b);
        REQUIRE(native(-portable(a)) == -a);
        REQUIRE((portable(a) < portable(b)) == (a < b));
        REQUIRE((portable(a) <= portable(b)) == (a <= b));
        REQUIRE(native(pathstream::magnitude(portable(a))) == (a < 0 ? -a : a));
    }
}

TEST_CASE("Int128 multiply agrees with __int128 when the product fits", "[int128]") {
    std::mt19937_64 rng(pathstream::test::property_seed());
    for (int i = 0; i < 200000; ++i) {
        const int a_bits = 1 + static_cast<int>(rng() % 62);
        const int b_bits = 1 + static_cast<int>(rng() % 62);
        const i128 a = random_value(rng) % (static_cast<i128>(1) << a_bits);
        const auto b =
            static_cast<std::int64_t>(rng() % (std::uint64_t{1} << b_bits)) * (rng() % 2 ? 1 : -1);
        REQUIRE(native(portable(a) * b) == a * b);
        REQUIRE(native(pathstream::multiply_portable(portable(a), b)) == a * b);
        // Beyond 2^127 both keep the product modulo 2^128, alike.
        const auto big = static_cast<std::int64_t>(rng());
        const Int128 shifted = portable(static_cast<i128>(static_cast<unsigned __int128>(a) << 64));
        REQUIRE(pathstream::multiply_portable(shifted, big) == shifted * big);
        const std::uint64_t x = rng(), y = rng();
        REQUIRE(native(pathstream::multiply_unsigned(x, y)) ==
                static_cast<i128>(static_cast<unsigned __int128>(x) * y));
    }
}

TEST_CASE("Int128 floor division agrees with __int128 for both signs and all sizes", "[int128]") {
    std::mt19937_64 rng(pathstream::test::property_seed());
    for (int i = 0; i < 200000; ++i) {
        const i128 a = random_value(rng);
        const int d_bits = 1 + static_cast<int>(rng() % 63);
        std::uint64_t d = rng() & ((std::uint64_t{1} << d_bits) - 1);
        if (d == 0) d = 1;
        const auto r = pathstream::floor_divide(portable(a), d);
        i128 q = a / static_cast<i128>(d);
        if (a % static_cast<i128>(d) != 0 && a < 0) --q;
        REQUIRE(native(r.quotient) == q);
        REQUIRE(static_cast<i128>(r.remainder) == a - q * static_cast<i128>(d));
        REQUIRE(r.remainder < d);
    }
}
