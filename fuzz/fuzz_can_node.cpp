// The native CAN node: any frames (any length field, any function, this node or another),
// ticks between. Every answer is a valid classic frame; a refused batch or configuration
// (ack result not 0) leaves the device's queue and configuration as they were.
#include "device_fingerprint.hpp"
#include "fuzz_support.hpp"
#include "pathstream/device/can_node.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    namespace pc = device::can;
    fuzz::Input in(data, size);
    const Lsb start[2] = {0, 0};
    device::MotionDevice<2, 16> d(start);
    pc::CanNode<2, 16> node(d, 5);
    if ((in.byte() & 1u) != 0) (void)d.configure(fuzz::fuzz_limits<2>());
    const std::uint32_t functions[] = {pc::kCommandBase,   pc::kCommandArgsBase, pc::kConfigBase,
                                       pc::kSpanStartBase, pc::kSpanDataBase,    pc::kSpanDataBase,
                                       pc::kSpanDataBase,  pc::kAckBase};
    while (!in.done()) {
        const std::uint8_t how = in.byte();
        pc::Frame f;
        f.id = pc::can_id(functions[how & 7u],
                          (how & 8u) != 0 ? static_cast<std::uint8_t>(in.byte() & 0x7Fu) : 5);
        // Mostly honest lengths; sometimes any byte (a corrupt driver or bus).
        f.length = (how & 16u) != 0 ? in.byte() : static_cast<std::uint8_t>(in.byte() % 9u);
        for (std::uint8_t& b : f.data) b = in.byte();
        const auto before = fuzz::fingerprint(d);
        bool refused = false;
        node.handle(f, [&](const pc::Frame& out) {
            if (out.length > 8) fuzz::violated("an answer longer than 8 bytes");
            pc::Ack a;
            if (pc::function_of(out.id) == pc::kAckBase && pc::decode_ack(out, a) &&
                a.kind != pc::kAckCommand && a.result != 0) {
                refused = true;
            }
        });
        if (refused) {
            const auto after = fuzz::fingerprint(d);
            // Queue, sequence and configuration (indices 0..6) are the write's to keep.
            for (std::size_t i = 0; i < 7; ++i) {
                if (after[i] != before[i])
                    fuzz::violated("a refused batch or configuration changed the device");
            }
        }
        if ((how & 32u) != 0) {
            Lsb position[2];
            d.tick(position);
            node.service();
        }
    }
    return 0;
}
