// DBC text from the protocol's declaration (device/can_protocol.hpp): one BO_ per message,
// one SG_ per signal (little-endian, scale 1), comments with the meaning, value tables.
#include "pathstream/machine/can_dbc.hpp"

#include <sstream>
#include <stdexcept>

#include "pathstream/device/can_protocol.hpp"

namespace pathstream::host {

std::string can_dbc(std::uint8_t node) {
    namespace pc = device::can;
    if (node < pc::kMinNode || node > pc::kMaxNode)
        throw std::invalid_argument("CAN node id outside 1..127");
    std::ostringstream o;
    o << "VERSION \"pathstream native CAN protocol " << unsigned(pc::kProtocolVersion) << ", node "
      << unsigned(node) << "\"\n\n\n"
      << "NS_ :\n\tCM_\n\tBA_DEF_\n\tBA_\n\tVAL_\n\n"
      << "BS_:\n\n"
      << "BU_: Host Device\n\n";
    for (const pc::Message& m : pc::kMessages) {
        const std::uint32_t id = pc::can_id(m.base, node);
        o << "\nBO_ " << id << ' ' << m.name << ": " << unsigned(m.length) << ' '
          << (m.from_device ? "Device" : "Host") << '\n';
        for (unsigned i = 0; i < m.signal_count; ++i) {
            const pc::Signal& s = m.signals[i];
            const unsigned bits = 8u * s.bytes;
            o << " SG_ " << s.name;
            if (s.mux == -2) o << " M";
            if (s.mux >= 0) o << " m" << s.mux;
            // Signed signals are two's complement: DBC's "-" and a range around zero.
            const unsigned long long max = bits >= 64 ? ~0ull : (1ull << bits) - 1;
            o << " : " << 8u * s.byte << '|' << bits << "@1" << (s.is_signed ? '-' : '+')
              << " (1,0) [";
            if (s.is_signed) {
                o << '-' << (max >> 1) + 1 << '|' << (max >> 1);
            } else {
                o << "0|" << max;
            }
            o << "] \"" << s.unit << "\" " << (m.from_device ? "Host" : "Device") << '\n';
        }
    }
    o << '\n';
    for (const pc::Message& m : pc::kMessages) {
        o << "CM_ BO_ " << pc::can_id(m.base, node) << " \"" << m.comment << " (id 0x" << std::hex
          << m.base << std::dec << " + node)\";\n";
    }
    for (const pc::Message& m : pc::kMessages) {
        for (unsigned i = 0; i < m.signal_count; ++i) {
            o << "CM_ SG_ " << pc::can_id(m.base, node) << ' ' << m.signals[i].name << " \""
              << m.signals[i].comment << "\";\n";
        }
    }
    for (const pc::Message& m : pc::kMessages) {
        for (unsigned i = 0; i < m.signal_count; ++i) {
            if (m.signals[i].values == nullptr) continue;
            o << "VAL_ " << pc::can_id(m.base, node) << ' ' << m.signals[i].name << ' '
              << m.signals[i].values << " ;\n";
        }
    }
    return o.str();
}

}  // namespace pathstream::host
