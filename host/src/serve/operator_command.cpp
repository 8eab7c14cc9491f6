// Operator commands go through `ctl`, the same program a user runs at a terminal: what the page
// or the broker asks is what `ctl` does and prints.
#include "operator_command.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "child_process.hpp"

namespace pathstream::host::serve {
namespace {

std::string number_text(double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%.6f", v);
    return text;
}

// The machine's own name for an axis the request names; anything else is refused.
std::string axis_name(const MachineProfile& machine, const nlohmann::json& v) {
    if (!v.is_string()) throw std::invalid_argument("axis: want an axis name");
    for (const AxisLimits& a : machine.axes) {
        if (a.name == v.get<std::string>()) return a.name;
    }
    throw std::invalid_argument("axis: the machine has no axis '" + v.get<std::string>() + "'");
}

}  // namespace

std::vector<std::string> operator_arguments(const OperatorTarget& to, const MachineProfile& machine,
                                            const nlohmann::json& request) {
    if (!request.is_object() || !request.contains("verb") || !request["verb"].is_string())
        return {};
    const std::string verb = request["verb"].get<std::string>();
    std::vector<std::string> argv = {to.executable, "ctl", "--machine=" + to.machine_file, "--json",
                                     "--wait=60"};
    std::vector<std::string> positional = {"--", to.target, verb};
    if (verb == "hold" || verb == "resume" || verb == "stop" || verb == "reset" || verb == "home") {
    } else if (verb == "pen") {
        if (!request.contains("down") || !request["down"].is_boolean())
            throw std::invalid_argument("pen: want down true or false");
        positional.push_back(request["down"].get<bool>() ? "down" : "up");
    } else if (verb == "jog") {
        positional.push_back(axis_name(machine, request.value("axis", nlohmann::json())));
        const nlohmann::json d = request.value("distance_mm", nlohmann::json());
        if (!d.is_number() || !std::isfinite(d.get<double>()) || d.get<double>() == 0 ||
            std::fabs(d.get<double>()) > 10000) {
            throw std::invalid_argument("jog: want distance_mm, not 0, at most 10000 either way");
        }
        positional.push_back(number_text(d.get<double>()));
        if (request.contains("feed")) {
            const nlohmann::json f = request["feed"];
            if (!f.is_number() || !(f.get<double>() > 0) || f.get<double>() > 1e6)
                throw std::invalid_argument("jog: feed in mm/s, > 0");
            argv.push_back("--feed=" + number_text(f.get<double>()));
        }
    } else {
        return {};
    }
    argv.insert(argv.end(), positional.begin(), positional.end());
    return argv;
}

std::pair<int, nlohmann::json> run_operator_command(const OperatorTarget& to,
                                                    const MachineProfile& machine,
                                                    const nlohmann::json& request,
                                                    const std::function<bool()>& give_up) {
    if (!request.is_object() || !request.contains("verb") || !request["verb"].is_string())
        return {400, {{"ok", false}, {"error", "want {\"verb\": ...}"}}};
    const std::string verb = request["verb"].get<std::string>();
    const std::vector<std::string> argv = operator_arguments(to, machine, request);
    if (argv.empty()) return {400, {{"ok", false}, {"error", "unknown verb '" + verb + "'"}}};
    // The device goes on when the caller gives up, as it does when `ctl` at a terminal is
    // interrupted.
    const ChildOutput r = run_child(argv, to.directory, give_up);
    nlohmann::json body{{"ok", r.exit_code == 0}, {"verb", verb}};
    if (!r.out.empty()) {
        try {
            body["result"] = nlohmann::json::parse(r.out);
        } catch (const std::exception&) {
            body["result"] = r.out;
        }
    }
    if (r.exit_code != 0) body["error"] = last_lines(r.err, 1);
    return {r.exit_code == 0 ? 200 : 422, body};
}

}  // namespace pathstream::host::serve
