// The device end of the native CAN protocol without a bus: batch assembly from span-start and
// span-data frames, a lost data frame refused as incomplete, a resent batch acknowledged as a
// duplicate, configuration sets, commands and status.
#include <catch2/catch.hpp>
#include <vector>

#include "pathstream/device/can_node.hpp"
#include "pathstream/device/wire_span.hpp"

using namespace pathstream;
namespace pc = device::can;

namespace {

struct Fixture {
    Lsb start[2] = {0, 0};
    device::MotionDevice<2, 16> dev{start};
    pc::CanNode<2, 16> node{dev, 5};
    std::vector<pc::Frame> out;

    void feed(const pc::Frame& f) {
        node.handle(f, [&](const pc::Frame& o) { out.push_back(o); });
    }
    pc::Ack last_ack() {
        REQUIRE(!out.empty());
        pc::Ack a;
        REQUIRE(pc::function_of(out.back().id) == pc::kAckBase);
        REQUIRE(pc::decode_ack(out.back(), a));
        return a;
    }
    void configure() {
        feed(pc::encode_config(5, 0, 2, 1000));
        for (unsigned a = 0; a < 2; ++a) {
            feed(pc::encode_config(5, pc::config_item_velocity(a), 2, 1000000));
            feed(pc::encode_config(5, pc::config_item_acceleration(a), 2, 100000000));
        }
        feed(pc::encode_config(5, pc::kConfigItemPenDown, 2, 40));
        const pc::Ack a = last_ack();
        REQUIRE(a.kind == pc::kAckConfig);
        REQUIRE(a.result == 0);
    }
    // Spans that creep along x: each 8 ticks, 10 LSB, at rest.
    std::vector<std::uint8_t> batch(unsigned count, std::int32_t from) {
        std::vector<std::uint8_t> p;
        for (unsigned i = 0; i < count; ++i) {
            device::WireSpan w;
            w.ticks = 8;
            w.end[0] = from + 10 * static_cast<std::int32_t>(i + 1);
            std::uint8_t b[64];
            const std::size_t n = device::encode_wire_span(w, 2, b, sizeof b);
            p.insert(p.end(), b, b + n);
        }
        return p;
    }
    void send_batch(std::uint32_t first, unsigned count, const std::vector<std::uint8_t>& p,
                    int skip = -1) {
        feed(pc::encode_span_start(
            5, {first, static_cast<std::uint8_t>(count), static_cast<std::uint16_t>(p.size())}));
        for (std::size_t i = 0; i < pc::data_frames(p.size()); ++i) {
            if (static_cast<int>(i) == skip) continue;
            feed(pc::encode_span_data(5, static_cast<std::uint8_t>(i), p.data(), p.size()));
        }
    }
};

}  // namespace

TEST_CASE("CAN node: a batch over frames is accepted whole, a resend is a duplicate", "[can]") {
    Fixture f;
    f.configure();
    const auto p = f.batch(3, 0);
    f.send_batch(1, 3, p);
    pc::Ack a = f.last_ack();
    CHECK((a.kind == pc::kAckSpans && a.result == 0 && a.sequence == 1 && a.free_slots == 13));
    CHECK(f.dev.last_accepted_sequence() == 3);
    f.send_batch(1, 3, p);
    a = f.last_ack();
    CHECK(a.result == 0);
    CHECK(f.dev.duplicates() == 1);
    CHECK(f.dev.queued_spans() == 3);
    CHECK(f.node.refused_batches() == 0);
}

TEST_CASE("CAN node: a lost data frame refuses the batch as incomplete, changing nothing",
          "[can]") {
    Fixture f;
    f.configure();
    const auto p = f.batch(3, 0);  // 3 x 28 bytes: 12 data frames
    f.send_batch(1, 3, p, 2);
    const pc::Ack a = f.last_ack();
    CHECK(a.result == pc::kResultIncomplete);
    CHECK(f.dev.queued_spans() == 0);
    CHECK(f.node.incomplete_transfers() == 1);
    f.send_batch(1, 3, p);
    CHECK(f.last_ack().result == 0);
    CHECK(f.dev.queued_spans() == 3);
}

TEST_CASE("CAN node: a lost last data frame leaves no answer, data without a start is ignored",
          "[can]") {
    Fixture f;
    f.configure();
    const auto p = f.batch(2, 0);  // 2 x 28 bytes: 8 data frames
    const int last = static_cast<int>(pc::data_frames(p.size())) - 1;
    const std::size_t before = f.out.size();
    f.send_batch(1, 2, p, last);
    CHECK(f.out.size() == before);
    f.feed(
        pc::encode_span_data(5, 0, p.data(), p.size()));  // transfer still waits for the last index
    CHECK(f.last_ack().result == pc::kResultIncomplete);
    const std::size_t after = f.out.size();
    f.feed(pc::encode_span_data(5, 0, p.data(), p.size()));  // no transfer: ignored
    CHECK(f.out.size() == after);
    CHECK(f.dev.queued_spans() == 0);
}

TEST_CASE("CAN node: bad sequence and limits are refused with the core status", "[can]") {
    Fixture f;
    f.configure();
    f.send_batch(2, 1, f.batch(1, 0));
    CHECK(f.last_ack().result == static_cast<std::uint8_t>(Status::kBadSequence));
    CHECK(f.node.refused_batches() == 1);
}

TEST_CASE("CAN node: configuration needs every item, commands and status answer", "[can]") {
    Fixture f;
    f.feed(pc::encode_config(5, 0, 2, 1000));
    f.feed(pc::encode_config(5, pc::config_item_acceleration(1), 2, 5));
    CHECK(f.out.empty());  // not the last item: no answer yet
    f.feed(pc::encode_config(5, pc::kConfigItemPenDown, 2, 5));
    CHECK(f.last_ack().result == pc::kResultIncomplete);
    CHECK_FALSE(f.dev.configured());
    f.feed(pc::encode_config(5, 5, 2, 5));  // axis 2's velocity: the device has two axes
    CHECK(f.last_ack().result == pc::kResultBadFrame);
    f.feed(pc::encode_config(5, 0, 3, 1000));
    CHECK(f.last_ack().result == static_cast<std::uint8_t>(Status::kBadLimits));
    f.feed(pc::encode_command(5, 1));
    CHECK(f.last_ack().result == static_cast<std::uint8_t>(Status::kNotConfigured));
    f.configure();
    CHECK(f.dev.limits().pen_down_ticks == 40);  // the pen-down delay item reached the device
    f.feed(pc::encode_command(5, 1));            // start with nothing queued: nothing would move
    CHECK((f.last_ack().kind == pc::kAckCommand && f.last_ack().sequence == 1 &&
           f.last_ack().result == static_cast<std::uint8_t>(Status::kNothingToResume)));
    f.feed(pc::encode_command(5, 4));  // stop while idle: drops nothing, accepted
    CHECK((f.last_ack().kind == pc::kAckCommand && f.last_ack().result == 0 &&
           f.last_ack().sequence == 4));
    f.feed(pc::encode_command(5, 9));  // no such command: the core refuses it
    CHECK(f.last_ack().result == static_cast<std::uint8_t>(Status::kUnknownCommand));
    f.out.clear();
    f.feed(pc::encode_command(5, pc::kCommandStatusRequest));
    REQUIRE(f.out.size() == pc::kStatusFrames + 2);  // A to D, then E for axes 0 and 1
    pc::Status3 s;
    s.position[0] = s.position[1] = -1;
    for (const auto& o : f.out) REQUIRE(pc::decode_status_part(o, s));
    CHECK((s.axes == 2 && s.version == pc::kProtocolVersion &&
           (s.flags & pc::kFlagConfigured) != 0 && s.free_slots == 16));
    CHECK((pc::function_of(f.out[4].id) == pc::kStatusEBase && f.out[4].data[0] == 0 &&
           f.out[5].data[0] == 1));
    CHECK((s.position[0] == f.dev.position(0) && s.position[1] == f.dev.position(1)));
    CHECK(s.epoch == (f.dev.epoch() & 0xFFFFu));
    f.out.clear();
    f.feed(pc::encode_command(6, pc::kCommandStatusRequest));  // another node
    CHECK(f.out.empty());
}
