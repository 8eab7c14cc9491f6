// The input shaper against an independent exact reference, on random jobs the setpoint stream
// plays: every shaped setpoint is the weighted sum of the unshaped ones rounded once, the shaped
// motion never moves, accelerates or jerks more than the command, and stays within the
// positions the command went through.
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <climits>
#include <cstdint>
#include <random>
#include <vector>

#include "core/property_settings.hpp"
#include "core/reference.hpp"
#include "pathstream/input_shaper.hpp"
#include "pathstream/setpoint_stream.hpp"

namespace {

using namespace pathstream;
using test::i128;

constexpr unsigned kAxes = 2;
constexpr std::uint32_t kHistory = 256;

/// A random job on the setpoint stream: Hermite spans through random points with random whole
/// velocities (LSB/tick), stops and dwells in between, from rest to rest. Returns every tick's
/// setpoints, [tick][axis], starting with the start point.
std::vector<std::array<Lsb, kAxes>> random_job(std::mt19937_64& rng) {
    std::uniform_int_distribution<int> spans_in_job(1, 30), ticks(1, 160), coin(0, 3);
    std::uniform_int_distribution<std::int32_t> velocity(-40, 40), start(-100000, 100000);
    Lsb origin[kAxes];
    for (Lsb& o : origin) o = start(rng);
    SetpointStream<kAxes, 64> stream(origin);
    std::array<std::int32_t, kAxes> at{}, v{};
    for (unsigned a = 0; a < kAxes; ++a) at[a] = origin[a];
    std::vector<std::array<Lsb, kAxes>> out{{origin[0], origin[1]}};
    const int spans = spans_in_job(rng);
    for (int s = 0; s < spans; ++s) {
        Span<kAxes> span;
        span.basis = Basis::kHermite;
        span.ticks = static_cast<std::uint32_t>(ticks(rng));
        const bool last = s + 1 == spans;
        const bool stop = last || coin(rng) == 0;
        for (unsigned a = 0; a < kAxes; ++a) {
            const std::int32_t next_v = stop ? 0 : velocity(rng);
            const auto n = static_cast<std::int32_t>(span.ticks);
            // The chord the mean velocity would cover, give or take a little.
            const std::int32_t chord = (v[a] + next_v) * n / 2 + velocity(rng);
            span.control[a][0] = at[a];
            span.control[a][1] = at[a] + chord;
            span.control[a][2] = v[a] * n;
            span.control[a][3] = next_v * n;
            at[a] += chord;
            v[a] = next_v;
        }
        REQUIRE(stream.push(span) == Status::kOk);
        Lsb tick_out[kAxes];
        while (stream.tick(tick_out) == TickState::kMoving)
            out.push_back({tick_out[0], tick_out[1]});
        out.push_back({tick_out[0], tick_out[1]});  // the end point, held
    }
    return out;
}

/// Random positive taps with increasing delays below kHistory whose weights sum to one.
std::vector<ShaperTap> random_taps(std::mt19937_64& rng) {
    std::uniform_int_distribution<std::uint32_t> count(1, kMaxShaperTaps);
    std::uniform_int_distribution<std::uint32_t> delay(0, kHistory - 1);
    const std::uint32_t n = count(rng);
    std::vector<std::uint32_t> delays;
    while (delays.size() < n) {
        const std::uint32_t d = delay(rng);
        if (std::find(delays.begin(), delays.end(), d) == delays.end()) delays.push_back(d);
    }
    std::sort(delays.begin(), delays.end());
    // n - 1 distinct cut points in 1..65535 split 65536 into n positive weights.
    std::uniform_int_distribution<std::uint32_t> cut(1, kShaperWeightOne - 1);
    std::vector<std::uint32_t> cuts;
    while (cuts.size() + 1 < n) {
        const std::uint32_t c = cut(rng);
        if (std::find(cuts.begin(), cuts.end(), c) == cuts.end()) cuts.push_back(c);
    }
    cuts.push_back(0);
    cuts.push_back(kShaperWeightOne);
    std::sort(cuts.begin(), cuts.end());
    std::vector<ShaperTap> taps;
    for (std::uint32_t i = 0; i < n; ++i) taps.push_back({delays[i], cuts[i + 1] - cuts[i]});
    return taps;
}

/// Largest |k-th difference| of a sequence.
template <typename T>
i128 max_difference(const std::vector<T>& x, int order) {
    std::vector<i128> d(x.begin(), x.end());
    for (int k = 0; k < order; ++k) {
        for (std::size_t i = 0; i + 1 < d.size(); ++i) d[i] = d[i + 1] - d[i];
        if (!d.empty()) d.pop_back();
    }
    i128 m = 0;
    for (i128 v : d) m = std::max(m, v < 0 ? -v : v);
    return m;
}

}  // namespace

TEST_CASE("shaped setpoints are the exact weighted sums of the command rounded once",
          "[shaper][property]") {
    std::mt19937_64 rng(test::property_seed());
    const std::uint64_t jobs = std::max<std::uint64_t>(test::g_spans_per_basis / 2000, 20);
    for (std::uint64_t job = 0; job < jobs; ++job) {
        const auto command = random_job(rng);
        std::vector<ShaperTap> taps[kAxes] = {random_taps(rng), random_taps(rng)};
        Lsb origin[kAxes] = {command[0][0], command[0][1]};
        InputShaper<kAxes, kHistory> shaper(origin);
        std::uint32_t longest = 0;
        for (unsigned a = 0; a < kAxes; ++a) {
            REQUIRE(shaper.configure(a, taps[a].data(),
                                     static_cast<std::uint32_t>(taps[a].size())) == Status::kOk);
            longest = std::max(longest, taps[a].back().delay);
        }
        REQUIRE(shaper.longest_delay() == longest);
        // The command as the shaper sees it: at rest at the start before the job, at rest at
        // the end for the longest delay after it.
        const std::size_t ticks = command.size() + longest + 1;
        auto input = [&](std::int64_t k, unsigned a) -> i128 {
            if (k < 0) return command.front()[a];
            if (k >= static_cast<std::int64_t>(command.size())) return command.back()[a];
            return command[static_cast<std::size_t>(k)][a];
        };
        std::vector<i128> sums[kAxes];
        std::vector<Lsb> shaped[kAxes], unshaped[kAxes];
        // The test's own ring of the commands, for the two sums on their own.
        Lsb ring[kAxes][kHistory];
        for (unsigned a = 0; a < kAxes; ++a)
            for (Lsb& r : ring[a]) r = origin[a];
        for (std::size_t k = 0; k < ticks; ++k) {
            Lsb in[kAxes], out[kAxes];
            for (unsigned a = 0; a < kAxes; ++a)
                in[a] = static_cast<Lsb>(input(static_cast<std::int64_t>(k), a));
            shaper.shape(in, out);
            const auto head = static_cast<std::uint32_t>(k % kHistory);
            for (unsigned a = 0; a < kAxes; ++a) {
                ring[a][head] = in[a];
                const auto count = static_cast<std::uint32_t>(taps[a].size());
                REQUIRE(shaped_sum_wide(taps[a].data(), count, ring[a], head, kHistory - 1) ==
                        out[a]);
                REQUIRE(shaped_sum_narrow(taps[a].data(), count, ring[a], head, kHistory - 1) ==
                        out[a]);
            }
            for (unsigned a = 0; a < kAxes; ++a) {
                i128 sum = 0;
                i128 lowest = input(static_cast<std::int64_t>(k), a), highest = lowest;
                for (const ShaperTap& t : taps[a]) {
                    const i128 u = input(static_cast<std::int64_t>(k) - t.delay, a);
                    sum += static_cast<i128>(t.weight) * u;
                }
                for (std::uint32_t d = 0; d <= taps[a].back().delay; ++d) {
                    const i128 u = input(static_cast<std::int64_t>(k) - d, a);
                    lowest = std::min(lowest, u);
                    highest = std::max(highest, u);
                }
                // floor(sum / 2^16 + 1/2), by the reference's own floor division.
                const i128 reference =
                    test::floor_div(2 * sum + kShaperWeightOne, 2 * i128{kShaperWeightOne});
                REQUIRE(static_cast<i128>(out[a]) == reference);
                REQUIRE(out[a] >= lowest);
                REQUIRE(out[a] <= highest);
                sums[a].push_back(sum);
                shaped[a].push_back(out[a]);
                unshaped[a].push_back(in[a]);
            }
        }
        for (unsigned a = 0; a < kAxes; ++a) {
            // The exact shaped motion never exceeds the command's velocity, acceleration or
            // jerk (a positive average of delayed copies); rounding it once adds at most
            // 1 LSB/tick^2 to the acceleration and 3 LSB/tick^3 to the jerk, nothing to the
            // velocity.
            for (int order = 1; order <= 3; ++order) {
                const i128 command_peak = max_difference(unshaped[a], order);
                CHECK(max_difference(sums[a], order) <= command_peak * kShaperWeightOne);
            }
            CHECK(max_difference(shaped[a], 1) <= max_difference(unshaped[a], 1));
            CHECK(max_difference(shaped[a], 2) <= max_difference(unshaped[a], 2) + 1);
            CHECK(max_difference(shaped[a], 3) <= max_difference(unshaped[a], 3) + 3);
            // Settled: the output is the command's end point again, exactly.
            CHECK(shaped[a].back() == command.back()[a]);
        }
        CHECK(shaper.settled());
    }
}

TEST_CASE("the 64-bit and the 32-bit sums agree with the reference on any setpoints",
          "[shaper][property]") {
    std::mt19937_64 rng(test::property_seed() + 1);
    std::uniform_int_distribution<std::int32_t> anywhere(INT32_MIN, INT32_MAX);
    std::uniform_int_distribution<int> style(0, 2);
    const std::uint64_t rounds = std::max<std::uint64_t>(test::g_spans_per_basis / 10, 1000);
    Lsb ring[kHistory];
    for (std::uint64_t round = 0; round < rounds; ++round) {
        const std::vector<ShaperTap> taps = random_taps(rng);
        // Anywhere in int32, or all at one extreme (the sums' worst cases), or mixed.
        const int s = style(rng);
        for (Lsb& r : ring)
            r = s == 0 ? anywhere(rng) : s == 1 ? INT32_MIN : (anywhere(rng) < 0 ? INT32_MAX : -1);
        const auto head = static_cast<std::uint32_t>(anywhere(rng)) % kHistory;
        i128 sum = 0;
        for (const ShaperTap& t : taps) sum += i128{t.weight} * ring[(head - t.delay) % kHistory];
        const i128 reference =
            test::floor_div(2 * sum + kShaperWeightOne, 2 * i128{kShaperWeightOne});
        const auto count = static_cast<std::uint32_t>(taps.size());
        REQUIRE(shaped_sum_wide(taps.data(), count, ring, head, kHistory - 1) == reference);
        REQUIRE(shaped_sum_narrow(taps.data(), count, ring, head, kHistory - 1) == reference);
    }
}

TEST_CASE("the shaper takes new taps only while settled", "[shaper]") {
    const Lsb origin[1] = {1000};
    InputShaper<1, 16> shaper(origin);
    const ShaperTap zv[2] = {{0, 32768}, {6, 32768}};
    REQUIRE(shaper.configure(0, zv, 2) == Status::kOk);
    Lsb out[1];
    const Lsb moved[1] = {1010};
    shaper.shape(moved, out);
    CHECK(out[0] == 1005);
    CHECK_FALSE(shaper.settled());
    CHECK(shaper.configure(0, zv, 1) == Status::kBadShaper);  // weights do not sum to one
    CHECK(shaper.configure(0, zv, 0) == Status::kWrongState);
    for (int k = 0; k < 5; ++k) shaper.shape(moved, out);
    CHECK(out[0] == 1005);
    CHECK_FALSE(shaper.settled());
    shaper.shape(moved, out);
    CHECK(out[0] == 1010);
    CHECK(shaper.settled());
    CHECK(shaper.configure(0, zv, 0) == Status::kOk);  // unshaped from here
    const Lsb back[1] = {1000};
    shaper.shape(back, out);
    CHECK(out[0] == 1000);
}

TEST_CASE("a coordinate jump is not smoothed into a motion", "[shaper]") {
    const Lsb origin[1] = {0};
    InputShaper<1, 16> shaper(origin);
    const ShaperTap ei[3] = {{0, 16384}, {4, 32768}, {8, 16384}};
    REQUIRE(shaper.configure(0, ei, 3) == Status::kOk);
    const Lsb jumped[1] = {5000};
    shaper.reset(jumped);
    Lsb out[1];
    shaper.shape(jumped, out);
    CHECK(out[0] == 5000);
    CHECK(shaper.settled());
}

TEST_CASE("shaper taps are checked", "[shaper]") {
    const ShaperTap good[2] = {{0, 40000}, {10, 25536}};
    CHECK(check_shaper_taps(good, 2, 16) == Status::kOk);
    CHECK(check_shaper_taps(good, 0, 16) == Status::kOk);
    CHECK(check_shaper_taps(good, 2, 10) == Status::kBadShaper);  // delay beyond the history
    const ShaperTap unordered[2] = {{5, 32768}, {5, 32768}};
    CHECK(check_shaper_taps(unordered, 2, 16) == Status::kBadShaper);
    const ShaperTap zero[3] = {{0, 32768}, {1, 0}, {2, 32768}};
    CHECK(check_shaper_taps(zero, 3, 16) == Status::kBadShaper);
    const ShaperTap over[2] = {{0, 65536}, {1, 1}};
    CHECK(check_shaper_taps(over, 2, 16) == Status::kBadShaper);
    ShaperTap many[kMaxShaperTaps + 1];
    for (std::uint32_t i = 0; i <= kMaxShaperTaps; ++i)
        many[i] = {i, i == 0 ? 65536 - kMaxShaperTaps : 1};
    CHECK(check_shaper_taps(many, kMaxShaperTaps + 1, 16) == Status::kBadShaper);
    CHECK(check_shaper_taps(many, kMaxShaperTaps, 16) == Status::kBadShaper);  // sum short by 1
    CHECK(check_shaper_taps(nullptr, 1, 16) == Status::kBadShaper);
}
