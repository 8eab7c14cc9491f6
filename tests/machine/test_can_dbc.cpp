// The DBC file is the protocol's declaration, printed: docs/pathstream.dbc must equal the
// generator's output byte for byte (regenerate: pathstream_can_dbc 1 > docs/pathstream.dbc),
// and the declaration itself must be consistent (signals inside their frames, no overlaps).
#include <catch2/catch.hpp>
#include <fstream>
#include <set>
#include <sstream>

#include "pathstream/device/can_protocol.hpp"
#include "pathstream/machine/can_dbc.hpp"

using namespace pathstream;
namespace pc = device::can;

TEST_CASE("docs/pathstream.dbc is generated from the protocol declaration", "[can][dbc]") {
    std::ifstream in(std::string(PATHSTREAM_SOURCE_DIR) + "/docs/pathstream.dbc", std::ios::binary);
    REQUIRE(in);
    std::ostringstream committed;
    committed << in.rdbuf();
    INFO("regenerate with: build/.../sim/can/pathstream_can_dbc 1 > docs/pathstream.dbc");
    CHECK(committed.str() == host::can_dbc(1));
}

TEST_CASE("the CAN protocol declaration is consistent", "[can][dbc]") {
    std::set<std::uint32_t> bases;
    for (const pc::Message& m : pc::kMessages) {
        INFO(m.name);
        CHECK(bases.insert(m.base).second);
        CHECK((m.base & 0x7Fu) == 0);
        CHECK(pc::function_of(pc::can_id(m.base, 127)) == m.base);
        CHECK(m.length <= 8);
        bool used[8] = {};
        for (unsigned i = 0; i < m.signal_count; ++i) {
            const pc::Signal& s = m.signals[i];
            INFO(s.name);
            REQUIRE(s.byte + s.bytes <= m.length + (m.base == pc::kSpanDataBase ? 0 : 0));
            if (s.mux >= 0 && s.mux != 0)
                continue;  // multiplexed values share bytes 2..5 with TickRate (m0)
            for (unsigned b = s.byte; b < s.byte + s.bytes; ++b) {
                CHECK_FALSE(used[b]);
                used[b] = true;
            }
        }
    }
    // Every id of every node stays a standard 11-bit identifier.
    CHECK(pc::can_id(pc::kSpanDataBase, pc::kMaxNode) <= 0x7FFu);
}

TEST_CASE("encoders and decoders agree with the declared layout", "[can][dbc]") {
    pc::Ack a{pc::kAckSpans, 7, 0x01020304u, 9, 1};
    const pc::Frame f = pc::encode_ack(5, a);
    CHECK(f.id == 0x185u);
    CHECK(f.data[2] == 0x04);  // little-endian, as the DBC says (@1)
    pc::Ack b;
    REQUIRE(pc::decode_ack(f, b));
    CHECK((b.kind == a.kind && b.result == a.result && b.sequence == a.sequence &&
           b.free_slots == 9 && b.state == 1));
    pc::Status3 s;
    s.state = 2;
    s.fault_code = 0x0103;
    s.last_accepted = 77;
    s.last_completed = 70;
    s.ticks_executed = 123456;
    s.axes = 4;
    s.version = 1;
    s.finished_job = 31;
    s.finished_job_ticks = 0x01020304u;
    pc::Frame out[pc::kStatusFrames];
    pc::encode_status(5, s, out);
    CHECK(out[3].id == 0x505u);
    pc::Status3 t;
    for (const auto& o : out) REQUIRE(pc::decode_status_part(o, t));
    CHECK((t.state == 2 && t.fault_code == 0x0103 && t.last_accepted == 77 &&
           t.last_completed == 70 && t.ticks_executed == 123456 && t.axes == 4 && t.version == 1));
    CHECK((t.finished_job == 31 && t.finished_job_ticks == 0x01020304u));
    // Status E: a negative position and the epoch's low 16 bits survive the trip.
    const pc::Frame e = pc::encode_status_axis(5, 3, -123456789, 0x12345u);
    CHECK(e.id == 0x585u);
    REQUIRE(pc::decode_status_part(e, t));
    CHECK((t.position[3] == -123456789 && t.epoch == 0x2345u));
    const pc::Frame bad_axis = pc::encode_status_axis(5, 8, 1, 0);
    CHECK_FALSE(pc::decode_status_part(bad_axis, t));
    const std::uint8_t payload[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
    CHECK(pc::data_frames(9) == 2);
    const pc::Frame d1 = pc::encode_span_data(5, 1, payload, 9);
    CHECK(d1.length == 3);
    CHECK((d1.data[0] == 1 && d1.data[1] == 8 && d1.data[2] == 9));
    CHECK(pc::frame_bits_worst_case(8) == 135);
    CHECK(pc::frame_bits_worst_case(0) == 55);
}
