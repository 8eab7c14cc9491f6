// The Modbus streaming client: SpanStreamer over a ModbusSession (docs/modbus.md).
#include "pathstream/host/modbus_stream.hpp"

#include "modbus_session.hpp"
#include "span_streamer.hpp"

namespace pathstream::host {

std::vector<Lsb> modbus_rest_position(const MachineProfile& profile, const StreamOptions& options) {
    const Plan none;
    PlanSupply supply(none);
    ModbusSession session(options);
    const StreamSettings settings = settings_of(options);
    return SpanStreamer(supply, profile, session, settings).rest_position();
}

StreamReport stream_modbus(const Plan& plan, const MachineProfile& profile,
                           const StreamOptions& options, const StreamProgress& progress) {
    PlanSupply supply(plan);
    return stream_modbus(supply, profile, options, plan_progress(progress));
}

StreamReport stream_modbus(SpanSupply& supply, const MachineProfile& profile,
                           const StreamOptions& options, const SupplyProgress& progress) {
    ModbusSession session(options);
    const StreamSettings settings = settings_of(options);
    StreamReport report;
    static_cast<StreamOutcome&>(report) =
        SpanStreamer(supply, profile, session, settings).run(progress);
    session.count_into(report);
    return report;
}

}  // namespace pathstream::host
