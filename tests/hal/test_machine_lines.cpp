// The machine-line concepts a firmware image drives its pins through (machine_lines.hpp) have
// the shape of the Linux side's virtual lines, so that code written against one reads the
// other; and a generic user of the concepts drives what it is given, in order.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "pathstream/hal/gpio.hpp"
#include "pathstream/hal/machine_lines.hpp"

using namespace pathstream::hal;

static_assert(OutputLine<DigitalOutput>);
static_assert(InputLevel<DigitalInput>);

namespace {

// A recording step/dir port: every call appended as (call, mask).
struct RecordedLines {
    std::vector<std::pair<char, std::uint32_t>> calls;
    void set_directions(std::uint32_t m) { calls.push_back({'d', m}); }
    void raise_steps(std::uint32_t m) { calls.push_back({'r', m}); }
    void lower_steps(std::uint32_t m) { calls.push_back({'l', m}); }
};
static_assert(StepDirLines<RecordedLines>);

struct NotLines {
    void set_directions(std::uint32_t) {}
};
static_assert(!StepDirLines<NotLines>);

// One pulse of the axes in `mask` after setting their directions: what a tick's first group does.
template <StepDirLines Lines>
void pulse(Lines& lines, std::uint32_t forward, std::uint32_t mask) {
    lines.set_directions(forward);
    lines.raise_steps(mask);
    lines.lower_steps(mask);
}

}  // namespace

TEST_CASE("machine lines: a step/dir port sees directions before the step edges", "[hal][lines]") {
    RecordedLines lines;
    pulse(lines, 0b01, 0b11);
    REQUIRE(lines.calls.size() == 3);
    CHECK(lines.calls[0] == std::pair<char, std::uint32_t>{'d', 0b01});
    CHECK(lines.calls[1] == std::pair<char, std::uint32_t>{'r', 0b11});
    CHECK(lines.calls[2] == std::pair<char, std::uint32_t>{'l', 0b11});
}
