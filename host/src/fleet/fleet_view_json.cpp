// The fleet's view as JSON: what `fleet status --json`, `fleet jobs --json` and the fleet
// page's GET /api/fleet print. Unknown numbers are null, never -1.
#include "pathstream/host/fleet_view.hpp"

namespace pathstream::host {

using Json = nlohmann::json;

namespace {

Json number_or_null(double v) {
    return v < 0 ? Json(nullptr) : Json(v);
}

}  // namespace

Json to_json(const FleetMachine& m) {
    Json position = Json::object();
    for (const auto& [axis, v] : m.position_mm) position[axis] = v;
    return Json{{"name", m.name},
                {"online", m.online},
                {"machine", m.machine_file},
                {"axes", m.axes},
                {"kind", m.kind},
                {"state", m.state},
                {"error", m.error},
                {"position_mm", position},
                {"fraction", number_or_null(m.fraction)},
                {"eta_s", number_or_null(m.eta_s)},
                {"job", m.job.empty() ? Json(nullptr) : Json(m.job)}};
}

Json to_json(const FleetJob& j) {
    Json history = Json::array();
    for (const FleetJobStep& s : j.history) {
        history.push_back(Json{{"state", s.state},
                               {"machine", s.machine.empty() ? Json(nullptr) : Json(s.machine)},
                               {"at", s.at}});
    }
    return Json{{"id", j.id},
                {"state", j.state},
                {"machine", j.machine.empty() ? Json(nullptr) : Json(j.machine)},
                {"file", j.file},
                {"at", j.at},
                {"error", j.error},
                {"history", history},
                {"fraction", number_or_null(j.fraction)},
                {"eta_s", number_or_null(j.eta_s)}};
}

Json FleetView::to_json() const {
    Json machines = Json::array();
    for (const FleetMachine& m : this->machines()) machines.push_back(host::to_json(m));
    Json jobs = Json::array();
    for (const FleetJob& j : this->jobs()) jobs.push_back(host::to_json(j));
    return Json{{"machines", machines}, {"jobs", jobs}, {"ignored", ignored_}};
}

}  // namespace pathstream::host
