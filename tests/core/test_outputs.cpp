// Span outputs (the pen) switch exactly at the first tick of the span that carries them.
#include <catch2/catch.hpp>

#include "pathstream/setpoint_stream.hpp"

using namespace pathstream;

TEST_CASE("outputs change at the first tick of their span and persist while idle",
          "[stream][outputs]") {
    const Lsb start[1] = {100};
    SetpointStream<1, 4> stream{start};
    Lsb out[1];
    CHECK(stream.tick(out) == TickState::kIdle);
    CHECK(stream.outputs() == 0);

    Span<1> still;  // pen going down while holding still: Hermite with zero tangents
    still.basis = Basis::kHermite;
    still.ticks = 3;
    still.outputs = kOutputPenDown;
    still.control[0][0] = still.control[0][1] = 100;
    Span<1> move = still;  // then a straight move with the pen down, then pen up
    move.ticks = 4;
    move.control[0][1] = 140;
    move.control[0][2] = move.control[0][3] = 40;
    Span<1> lift = still;
    lift.outputs = 0;
    lift.control[0][0] = lift.control[0][1] = 140;
    REQUIRE(stream.push(still) == Status::kOk);
    REQUIRE(stream.push(move) == Status::kOk);
    REQUIRE(stream.push(lift) == Status::kOk);

    const std::uint8_t expected[] = {1, 1, 1, 1, 1, 1, 1, 0, 0, 0};
    const Lsb position[] = {100, 100, 100, 100, 110, 120, 130, 140, 140, 140};
    for (int k = 0; k < 10; ++k) {
        INFO("tick " << k);
        REQUIRE(stream.tick(out) == TickState::kMoving);
        CHECK(out[0] == position[k]);
        CHECK(stream.outputs() == expected[k]);
    }
    CHECK(stream.tick(out) == TickState::kIdle);
    CHECK(stream.outputs() == 0);
    CHECK(out[0] == 140);
}
