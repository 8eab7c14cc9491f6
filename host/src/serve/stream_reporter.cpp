// A stream reports through the same bridge as serve: its events fill a hub of their own, which
// the bridge forwards; the sticky kinds are the ones serve keeps.
#include "stream_reporter.hpp"

#include <filesystem>

namespace pathstream::host::serve {

StreamReporter::StreamReporter(MqttLink link, MachineProfile machine, OperatorTarget target,
                               const std::string& machine_file)
    : machine_(std::move(machine)), target_(std::move(target)) {
    nlohmann::json axes = nlohmann::json::array();
    for (const AxisLimits& a : machine_.axes) axes.push_back(a.name);
    nlohmann::json identity{{"name", link.name},
                            {"kind", nullptr},
                            {"machine", std::filesystem::path(machine_file).filename().string()},
                            {"axes", axes},
                            {"target", target_.target},
                            {"command", "stream"}};
    bridge_ = std::make_unique<MqttBridge>(
        std::move(link), hub_,
        [this](const nlohmann::json& request) {
            return run_operator_command(target_, machine_, request, [] { return false; });
        },
        std::move(identity));
}

StreamReporter::~StreamReporter() {
    stop();
}

void StreamReporter::start() {
    bridge_->start();
}

void StreamReporter::event(const std::string& line) {
    hub_.publish(line, job_sticky_kind(line));
}

void StreamReporter::stop() {
    if (!bridge_) return;
    // The last events (job_end) reach the broker before the machine says it is offline.
    bridge_->stop();
    hub_.close();
}

}  // namespace pathstream::host::serve
