// The CAN node never trusts a frame's length field: a frame claiming more than 8 data bytes is
// refused with kResultBadFrame before any byte is read, and drops the transfer it belongs to.
#include <catch2/catch.hpp>
#include <cstdint>
#include <vector>

#include "pathstream/device/can_node.hpp"
#include "pathstream/device/wire_span.hpp"

using namespace pathstream;
namespace pc = device::can;

namespace {

struct Node {
    Lsb start[2] = {0, 0};
    device::MotionDevice<2, 16> dev{start};
    pc::CanNode<2, 16> node{dev, 5};
    std::vector<pc::Frame> out;

    void feed(const pc::Frame& f) {
        node.handle(f, [&](const pc::Frame& o) { out.push_back(o); });
    }
    pc::Ack last_ack() const {
        pc::Ack a;
        REQUIRE(!out.empty());
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
        REQUIRE(last_ack().result == 0);
    }
};

// Two spans creeping along x (56 bytes: 8 data frames).
std::vector<std::uint8_t> two_spans() {
    std::vector<std::uint8_t> p;
    for (std::int32_t i = 1; i <= 2; ++i) {
        device::WireSpan w;
        w.ticks = 8;
        w.end[0] = 10 * i;
        std::uint8_t b[64];
        const std::size_t n = device::encode_wire_span(w, 2, b, sizeof b);
        p.insert(p.end(), b, b + n);
    }
    return p;
}

}  // namespace

TEST_CASE("CAN node refuses span data longer than a frame", "[can]") {
    Node n;
    n.configure();
    const auto p = two_spans();
    n.feed(pc::encode_span_start(5, {1, 2, static_cast<std::uint16_t>(p.size())}));
    for (const std::uint8_t length : {std::uint8_t{9}, std::uint8_t{255}}) {
        pc::Frame data = pc::encode_span_data(5, 0, p.data(), p.size());
        data.length = length;
        const std::size_t answers = n.out.size();
        n.feed(data);
        REQUIRE(n.out.size() == answers + 1);
        const pc::Ack a = n.last_ack();
        CHECK(a.kind == pc::kAckSpans);
        CHECK(a.result == pc::kResultBadFrame);
        n.feed(pc::encode_span_start(5, {1, 2, static_cast<std::uint16_t>(p.size())}));
    }
    CHECK(n.node.refused_batches() == 2);
    CHECK(n.dev.queued_spans() == 0);
    // The rest of the dropped transfer is ignored; a clean resend is accepted.
    n.feed(pc::encode_span_data(5, 0, p.data(), p.size()));
    n.feed(pc::encode_span_start(5, {1, 2, static_cast<std::uint16_t>(p.size())}));
    for (std::size_t i = 0; i < pc::data_frames(p.size()); ++i) {
        n.feed(pc::encode_span_data(5, static_cast<std::uint8_t>(i), p.data(), p.size()));
    }
    CHECK(n.last_ack().result == 0);
    CHECK(n.dev.queued_spans() == 2);
}

TEST_CASE("CAN node refuses oversized commands and configuration", "[can]") {
    Node n;
    pc::Frame config = pc::encode_config(5, 0, 2, 1000);
    config.length = 12;
    n.feed(config);
    CHECK(n.last_ack().kind == pc::kAckConfig);
    CHECK(n.last_ack().result == pc::kResultBadFrame);
    pc::Frame status{pc::can_id(pc::kCommandBase, 5), 9, {pc::kCommandStatusRequest}};
    n.feed(status);
    REQUIRE(n.out.size() == 2);  // a refusal, not the status frames
    CHECK(n.last_ack().kind == pc::kAckCommand);
    CHECK(n.last_ack().result == pc::kResultBadFrame);
    CHECK_FALSE(n.dev.configured());
}

TEST_CASE("CAN node refuses a resend with other bytes under the same sequence", "[can]") {
    Node n;
    n.configure();
    const auto p = two_spans();
    auto other = p;
    other[7] ^= 1;  // the first span's end moves by one LSB
    const auto send = [&](const std::vector<std::uint8_t>& payload, std::uint32_t first = 1,
                          std::uint8_t count = 2) {
        n.feed(
            pc::encode_span_start(5, {first, count, static_cast<std::uint16_t>(payload.size())}));
        for (std::size_t i = 0; i < pc::data_frames(payload.size()); ++i) {
            n.feed(pc::encode_span_data(5, static_cast<std::uint8_t>(i), payload.data(),
                                        payload.size()));
        }
        return n.last_ack();
    };
    CHECK(send(p).result == 0);
    CHECK(send(other).result == static_cast<std::uint8_t>(Status::kBadSequence));
    CHECK(n.dev.duplicates() == 0);
    CHECK(send(p).result == 0);
    CHECK(n.dev.duplicates() == 1);
    CHECK(n.dev.queued_spans() == 2);
    // The last span alone under its number is no resend of the batch, even with its bytes: a
    // part of a batch cannot be compared with the batch's CRC.
    const std::vector<std::uint8_t> tail(p.begin() + 28, p.end());
    CHECK(send(tail, 2, 1).result == static_cast<std::uint8_t>(Status::kBadSequence));
    CHECK(n.dev.duplicates() == 1);
    CHECK(n.dev.queued_spans() == 2);
}
