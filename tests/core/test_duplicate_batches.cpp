// Duplicate batches are told from different batches by the core itself: a resend of the last
// accepted batch is acknowledged only when its bytes carry the same CRC-32, whichever
// transport delivered it, and nothing but the last batch counts as a resend.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "core/device_fixture.hpp"
#include "pathstream/device/batch_crc.hpp"
#include "pathstream/device/motion_device.hpp"

using namespace pathstream;
using namespace pathstream::device;
using pathstream::test::batch_bytes;
using pathstream::test::test_limits;
using pathstream::test::trapezoid_move;

namespace {

constexpr unsigned kAxes = 2;
using Device = MotionDevice<kAxes, 16>;

Status send(Device& d, std::uint32_t sequence, const std::vector<std::uint8_t>& bytes,
            std::size_t count) {
    return d.accept_batch(sequence, static_cast<std::uint16_t>(count), bytes.data(), bytes.size());
}

}  // namespace

TEST_CASE("batch CRC-32 is the IEEE CRC-32", "[device]") {
    const std::uint8_t digits[] = {'1', '2', '3', '4', '5', '6', '7', '8', '9'};
    CHECK(batch_crc32(digits, sizeof digits) == 0xCBF43926u);  // the standard check value
    CHECK(batch_crc32(digits, 0) == 0u);
}

TEST_CASE("a resend of the last batch with any bit changed is refused by the core", "[device]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 20000, 8);
    const auto batch = batch_bytes<kAxes>(spans, 0, 3);
    REQUIRE(send(d, 1, batch, 3) == Status::kOk);

    std::size_t refused = 0;
    for (std::size_t byte = 0; byte < batch.size(); ++byte) {
        for (unsigned bit = 0; bit < 8; ++bit) {
            auto other = batch;
            other[byte] = static_cast<std::uint8_t>(other[byte] ^ (1u << bit));
            if (send(d, 1, other, 3) == Status::kBadSequence) ++refused;
        }
    }
    CHECK(refused == 8 * batch.size());
    CHECK(d.duplicates() == 0);
    CHECK(d.queued_spans() == 3);
    CHECK(d.last_accepted_sequence() == 3);

    // One byte more or less under the same numbers is not the same batch either.
    auto longer = batch;
    longer.push_back(0);
    CHECK(send(d, 1, longer, 3) == Status::kBadSequence);
    const std::vector<std::uint8_t> shorter(batch.begin(), batch.end() - 1);
    CHECK(send(d, 1, shorter, 3) == Status::kBadSequence);

    // The true resend is acknowledged, not queued again, as often as it comes.
    CHECK(send(d, 1, batch, 3) == Status::kOk);
    CHECK(send(d, 1, batch, 3) == Status::kOk);
    CHECK(d.duplicates() == 2);
    CHECK(d.queued_spans() == 3);
    CHECK(d.last_accepted_sequence() == 3);
}

TEST_CASE("only the last batch, whole, is a resend", "[device]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 20000, 8);
    const auto first = batch_bytes<kAxes>(spans, 0, 3);
    const auto second = batch_bytes<kAxes>(spans, 3, 2);
    REQUIRE(send(d, 1, first, 3) == Status::kOk);
    REQUIRE(send(d, 4, second, 2) == Status::kOk);

    // The batch before the last, and the tail of the last: their bytes cannot be compared.
    CHECK(send(d, 1, first, 3) == Status::kBadSequence);
    CHECK(send(d, 5, batch_bytes<kAxes>(spans, 4, 1), 1) == Status::kBadSequence);
    CHECK(send(d, 3, batch_bytes<kAxes>(spans, 2, 3), 3) == Status::kBadSequence);
    CHECK(d.duplicates() == 0);
    CHECK(send(d, 4, second, 2) == Status::kOk);
    CHECK(d.duplicates() == 1);
    CHECK(d.queued_spans() == 5);
    CHECK(d.last_accepted_sequence() == 5);
}

TEST_CASE("a refused batch leaves the resend check on the last accepted one", "[device]") {
    const Lsb start[kAxes] = {0, 0};
    Device d(start);
    REQUIRE(d.configure(test_limits<kAxes>()) == Status::kOk);
    const auto spans = trapezoid_move<kAxes>(start, 20000, 8);
    const auto first = batch_bytes<kAxes>(spans, 0, 3);
    REQUIRE(send(d, 1, first, 3) == Status::kOk);
    auto bad = spans;
    bad[4].end[0] += 4000;  // a kink far over the acceleration limit
    CHECK(send(d, 4, batch_bytes<kAxes>(bad, 3, 2), 2) == Status::kAccelerationLimit);
    CHECK(send(d, 1, first, 3) == Status::kOk);
    CHECK(d.duplicates() == 1);
    CHECK(send(d, 4, batch_bytes<kAxes>(spans, 3, 2), 2) == Status::kOk);
    CHECK(d.last_accepted_sequence() == 5);
}
