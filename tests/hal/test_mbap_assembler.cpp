// The server's MBAP frame assembler: a request arriving a byte at a time, or all at once, is
// one frame; headers no request has are refused at once.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "../../hal/src/mbap_assembler.hpp"

using pathstream::hal::detail::MbapAssembler;
using State = MbapAssembler::State;

namespace {

// Feeds `bytes` in pieces of at most `piece`, as the reads would; returns the last state and
// the bytes taken.
std::pair<State, std::size_t> feed(MbapAssembler& a, const std::vector<std::uint8_t>& bytes,
                                   std::size_t piece) {
    State s = State::kPartial;
    std::size_t at = 0;
    while (at < bytes.size() && s == State::kPartial) {
        const std::size_t n = std::min({piece, a.wanted(), bytes.size() - at});
        std::copy(bytes.begin() + static_cast<long>(at), bytes.begin() + static_cast<long>(at + n),
                  a.write_pointer());
        at += n;
        s = a.added(n);
    }
    return {s, at};
}

const std::vector<std::uint8_t> kRead = {0, 7, 0, 0, 0, 6, 1, 4, 0, 0, 0, 2};  // FC4, 2 registers

}  // namespace

TEST_CASE("MBAP: a request a byte at a time or whole is one frame", "[modbus][tcp]") {
    for (const std::size_t piece : {std::size_t{1}, std::size_t{5}, std::size_t{260}}) {
        MbapAssembler a;
        std::vector<std::uint8_t> two = kRead;
        two.insert(two.end(), kRead.begin(), kRead.end());  // a pipelined second request
        const auto [state, taken] = feed(a, two, piece);
        CHECK(state == State::kComplete);
        CHECK(taken == kRead.size());  // never a byte of the next request
        CHECK(a.size() == kRead.size());
        CHECK(a.wanted() == 0);
        CHECK(std::vector<std::uint8_t>(a.frame(), a.frame() + a.size()) == kRead);
        a.clear();
        CHECK(a.empty());
        CHECK(a.wanted() == MbapAssembler::kHeaderBytes);
    }
}

TEST_CASE("MBAP: a header no request has is refused", "[modbus][tcp]") {
    const std::vector<std::vector<std::uint8_t>> bad = {
        {0, 1, 0, 1, 0, 6, 1},    // protocol id 1
        {0, 1, 0, 0, 0, 1, 1},    // length 1: no function code
        {0, 1, 0, 0, 0, 255, 1},  // length 255: more than an ADU holds
        {0, 1, 0, 0, 1, 0, 1},    // length 256
    };
    for (const auto& header : bad) {
        MbapAssembler a;
        CHECK(feed(a, header, 1).first == State::kBad);
    }
    MbapAssembler longest;
    std::vector<std::uint8_t> frame = {0, 1, 0, 0, 0, 254};
    frame.resize(MbapAssembler::kMaxFrameBytes, 0);
    CHECK(feed(longest, frame, 64).first == State::kComplete);
}
