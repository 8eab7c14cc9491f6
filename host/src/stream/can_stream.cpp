// The native CAN streaming client: SpanStreamer over a CanSession (docs/can.md), and the
// can:// target's parser.
#include "pathstream/host/can_stream.hpp"

#include <sstream>
#include <stdexcept>

#include "can_session.hpp"
#include "pathstream/device/can_protocol.hpp"
#include "span_streamer.hpp"

namespace pathstream::host {
namespace pc = device::can;

CanTarget parse_can_target(const std::string& url) {
    const std::string scheme = "can://";
    if (url.compare(0, scheme.size(), scheme) != 0)
        throw std::invalid_argument("not a can:// target: " + url);
    const std::string rest = url.substr(scheme.size());
    const auto q = rest.find('?');
    CanTarget t;
    t.interface_name = rest.substr(0, q);
    if (t.interface_name.empty())
        throw std::invalid_argument(url + ": no CAN interface (can://IFACE?node=N)");
    bool have_node = false;
    std::string query = q == std::string::npos ? "" : rest.substr(q + 1);
    std::istringstream in(query);
    std::string item;
    while (std::getline(in, item, '&')) {
        if (item.empty()) continue;
        const auto eq = item.find('=');
        const std::string key = item.substr(0, eq),
                          value = eq == std::string::npos ? "" : item.substr(eq + 1);
        if (key == "node") {
            std::size_t used = 0;
            int n = -1;
            try {
                n = std::stoi(value, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used != value.size() || value.empty() || n < pc::kMinNode || n > pc::kMaxNode) {
                throw std::invalid_argument(url + ": node must be 1..127, not '" + value + "'");
            }
            t.node = static_cast<std::uint8_t>(n);
            have_node = true;
        } else if (key == "protocol") {
            if (value != "native" && value != "cia402") {
                throw std::invalid_argument(url + ": protocol must be native or cia402, not '" +
                                            value + "'");
            }
            t.protocol = value;
        } else {
            throw std::invalid_argument(url + ": unknown parameter '" + key + "' (node, protocol)");
        }
    }
    if (!have_node) throw std::invalid_argument(url + ": node=N (1..127) missing");
    return t;
}

std::vector<Lsb> can_rest_position(const MachineProfile& profile, hal::CanBus& bus,
                                   const CanStreamOptions& options) {
    const Plan none;
    PlanSupply supply(none);
    CanStreamReport counters;
    CanSession session(bus, options, counters);
    const StreamSettings settings = settings_of(options);
    return SpanStreamer(supply, profile, session, settings).rest_position();
}

CanStreamReport stream_can(const Plan& plan, const MachineProfile& profile, hal::CanBus& bus,
                           const CanStreamOptions& options, const StreamProgress& progress) {
    PlanSupply supply(plan);
    return stream_can(supply, profile, bus, options, plan_progress(progress));
}

CanStreamReport stream_can(SpanSupply& supply, const MachineProfile& profile, hal::CanBus& bus,
                           const CanStreamOptions& options, const SupplyProgress& progress) {
    CanStreamReport report;
    CanSession session(bus, options, report);
    const StreamSettings settings = settings_of(options);
    const StreamOutcome outcome = SpanStreamer(supply, profile, session, settings).run(progress);
    static_cast<StreamOutcome&>(report) = outcome;
    return report;
}

}  // namespace pathstream::host
