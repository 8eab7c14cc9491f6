// An operator's command (hold, resume, stop, reset, home, pen, jog) as JSON, run by this
// binary's `ctl` command against the device: for serve's page, its MQTT command topic and
// stream --mqtt alike (docs/serve.md, docs/mqtt.md).
#pragma once

#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "pathstream/machine/machine.hpp"

namespace pathstream::host::serve {

/// Who runs the commands and against what.
struct OperatorTarget {
    std::string executable;    ///< this program
    std::string machine_file;  ///< the profile, absolute
    std::string target;        ///< the device's URL
    std::string directory;     ///< where `ctl` runs
};

/// The `ctl` command line for `request` ({"verb": ..., fields}). Options come first, then
/// `--`: no value of the request can become an option. Throws std::invalid_argument naming
/// what is wrong (an unknown axis, a jog distance out of range); returns an empty vector for a
/// request without a verb or with an unknown one, which `run_operator_command` answers 400.
std::vector<std::string> operator_arguments(const OperatorTarget& to, const MachineProfile& machine,
                                            const nlohmann::json& request);

/// Runs `request` and answers as POST /api/control does: 200 {"ok": true, "verb", "result"},
/// 400 for a malformed request, 422 {"ok": false, "error"} when the device refuses. Waits for
/// `ctl` (home: up to a minute) unless `give_up` says to. Throws std::invalid_argument as
/// operator_arguments does.
std::pair<int, nlohmann::json> run_operator_command(const OperatorTarget& to,
                                                    const MachineProfile& machine,
                                                    const nlohmann::json& request,
                                                    const std::function<bool()>& give_up);

}  // namespace pathstream::host::serve
