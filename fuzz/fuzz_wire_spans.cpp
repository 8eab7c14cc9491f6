// Wire spans and batches: a decoded span re-encodes to the bytes it came from; a batch the
// device refuses changes no device state; an accepted one queues exactly its spans.
#include <vector>

#include "device_fingerprint.hpp"
#include "fuzz_support.hpp"
#include "pathstream/device/wire_span.hpp"

namespace {

using namespace pathstream;

// decode -> encode is the identity on the bytes consumed (T0 is not sent when continued).
void check_round_trip(const std::uint8_t* bytes, std::size_t size, unsigned axes) {
    device::WireSpan w;
    std::size_t consumed = 0;
    if (device::decode_wire_span(bytes, size, axes, w, consumed) != Status::kOk) return;
    if (consumed != device::wire_span_bytes(axes, (w.flags & device::kWireContinueTangent) != 0)) {
        fuzz::violated("consumed bytes differ from the span's size");
    }
    std::uint8_t again[4 + 8 * 12];
    const std::size_t n = device::encode_wire_span(w, axes, again, sizeof again);
    if (n != consumed) fuzz::violated("re-encoded span has another size");
    for (std::size_t i = 0; i < n; ++i) {
        if (again[i] != bytes[i]) fuzz::violated("re-encoded span differs");
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    fuzz::Input in(data, size);
    const unsigned axes = 1 + in.byte() % 8u;
    check_round_trip(in.here(), in.left(), axes);

    const Lsb start[2] = {0, 0};
    device::MotionDevice<2, 16> d(start);
    (void)d.configure(fuzz::fuzz_limits<2>());
    while (!in.done()) {
        const std::uint32_t first = 1 + in.byte() % 40u;
        const std::uint16_t count = static_cast<std::uint16_t>(in.byte() % 12u);
        const std::size_t length = std::min<std::size_t>(in.byte(), in.left());
        const std::vector<std::uint8_t> payload(in.here(), in.here() + length);
        in.skip(length);
        const auto before = fuzz::fingerprint(d);
        const std::uint32_t duplicates = d.duplicates(), queued = d.queued_spans();
        const Status s = d.accept_batch(first, count, payload.data(), payload.size());
        if (s != Status::kOk && fuzz::fingerprint(d) != before)
            fuzz::violated("a refused batch changed the device");
        if (s == Status::kOk && d.duplicates() == duplicates &&
            d.queued_spans() != queued + count) {
            fuzz::violated("an accepted batch did not queue its spans");
        }
        Lsb position[2];
        for (unsigned t = in.byte() % 64u; t > 0; --t) d.tick(position);
    }
    return 0;
}
