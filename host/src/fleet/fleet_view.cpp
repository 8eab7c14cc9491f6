// Folding the broker's messages into the fleet: every field read is checked for its type, so
// that anything anyone publishes under pathstream/ can only be ignored, never crash a watcher.
#include "pathstream/host/fleet_view.hpp"

#include <algorithm>

namespace pathstream::host {
namespace {

using Json = nlohmann::json;

constexpr std::size_t kMaxText = 1024;  // a file name or an error: longer ones are cut
constexpr int kMaxDepth = 16;           // our payloads nest 3 deep; a deeper one is not ours

// True when the JSON text nests at most `limit` deep (strings skipped): a hostile payload of
// 100 000 brackets is refused before it reaches the parser or a recursive destructor.
bool shallow(const std::string& text, int limit) {
    int depth = 0;
    bool in_string = false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (in_string) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > limit) return false;
        } else if (c == ']' || c == '}') {
            --depth;
        }
    }
    return true;
}

// The payload as a JSON object, or a discarded value.
Json object_of(const std::string& payload) {
    if (payload.size() > kFleetMaxPayload || !shallow(payload, kMaxDepth)) return Json();
    Json j = Json::parse(payload, nullptr, false);
    return j.is_object() ? j : Json();
}

// A field that must be a string when present: false for another type.
bool read_text(const Json& j, const char* key, std::string& out) {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return true;
    if (!it->is_string()) return false;
    out = it->get<std::string>().substr(0, kMaxText);
    return true;
}

// A field that must be a number when present (null: unknown, -1).
bool read_number(const Json& j, const char* key, double& out) {
    const auto it = j.find(key);
    if (it == j.end()) return true;
    if (it->is_null()) {
        out = -1;
        return true;
    }
    if (!it->is_number()) return false;
    out = it->get<double>();
    return true;
}

const char* const kStates[] = {"queued", "running", "done",        "held",   "stopped",
                               "failed", "refused", "interrupted", "dropped"};

bool is_job_state(const std::string& s) {
    return std::find(std::begin(kStates), std::end(kStates), s) != std::end(kStates);
}

bool is_active(const std::string& state) {
    return state == "running" || state == "held" || state == "interrupted";
}

}  // namespace

bool is_final_job_state(const std::string& s) {
    return s == "done" || s == "failed" || s == "stopped" || s == "refused" || s == "dropped";
}

bool is_fleet_name(const std::string& text) {
    if (text.empty() || text.size() > 64) return false;
    return std::all_of(text.begin(), text.end(), [](char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '-';
    });
}

bool FleetView::apply(const std::string& topic, const std::string& payload) {
    // pathstream/NAME/LEAF or pathstream/jobs/ID/LEAF; anything else is not described here.
    const std::string prefix = "pathstream/";
    if (topic.compare(0, prefix.size(), prefix) != 0) return false;
    std::vector<std::string> levels;
    std::size_t at = prefix.size();
    while (levels.size() < 4) {
        const std::size_t end = std::min(topic.find('/', at), topic.size());
        levels.push_back(topic.substr(at, end - at));
        if (end == topic.size()) break;
        at = end + 1;
    }
    bool ok = true;
    if (levels.size() == 3 && levels[0] == "jobs") {
        if (levels[2] != "state" && levels[2] != "progress") return false;
        ok = is_fleet_name(levels[1]) && apply_job(levels[1], levels[2], payload);
    } else if (levels.size() == 2 && levels[0] != "jobs" && levels[0] != "queue") {
        if (levels[1] != "online" && levels[1] != "status" && levels[1] != "progress") return false;
        ok = is_fleet_name(levels[0]) && apply_machine(levels[0], levels[1], payload);
    } else {
        return false;
    }
    ok ? ++applied_ : ++ignored_;
    return ok;
}

FleetMachine* FleetView::machine_slot(const std::string& name) {
    const auto it = machines_.find(name);
    if (it != machines_.end()) return &it->second;
    if (machines_.size() >= kFleetMaxMachines) return nullptr;
    FleetMachine& m = machines_[name];
    m.name = name;
    return &m;
}

FleetJob* FleetView::job_slot(const std::string& id) {
    const auto it = jobs_.find(id);
    if (it != jobs_.end()) return &it->second;
    if (jobs_.size() >= kFleetMaxJobs) {
        // The oldest finished job makes room: an active job is what the watcher is for.
        auto oldest = jobs_.end();
        for (auto j = jobs_.begin(); j != jobs_.end(); ++j) {
            if (is_final_job_state(j->second.state) &&
                (oldest == jobs_.end() || j->second.at < oldest->second.at))
                oldest = j;
        }
        if (oldest == jobs_.end()) return nullptr;
        jobs_.erase(oldest);
    }
    FleetJob& j = jobs_[id];
    j.id = id;
    return &j;
}

bool FleetView::apply_machine(const std::string& name, const std::string& leaf,
                              const std::string& payload) {
    if (payload.empty()) {
        // A retained message cleared: the machine's record of that topic is gone.
        if (leaf == "online") machines_.erase(name);
        return true;
    }
    const Json j = object_of(payload);
    if (j.is_discarded() || j.is_null()) return false;
    FleetMachine probe;  // read into a copy: a half-valid message changes nothing
    if (const auto it = machines_.find(name); it != machines_.end()) probe = it->second;
    probe.name = name;
    if (leaf == "online") {
        const auto online = j.find("online");
        if (online == j.end() || !online->is_boolean()) return false;
        probe.online = online->get<bool>();
        if (!read_text(j, "machine", probe.machine_file) || !read_text(j, "kind", probe.kind))
            return false;
        if (const auto axes = j.find("axes"); axes != j.end()) {
            if (!axes->is_array() || axes->size() > 16) return false;
            probe.axes.clear();
            for (const Json& a : *axes) {
                if (!a.is_string()) return false;
                probe.axes.push_back(a.get<std::string>().substr(0, 16));
            }
        }
    } else if (leaf == "status") {
        std::string error;
        if (!read_text(j, "error", error)) return false;
        probe.error = error;
        if (error.empty()) {
            if (!read_text(j, "state", probe.state)) return false;
            if (const auto p = j.find("position_mm"); p != j.end()) {
                if (!p->is_object() || p->size() > 16) return false;
                probe.position_mm.clear();
                for (const auto& [axis, v] : p->items()) {
                    if (!v.is_number()) return false;
                    probe.position_mm[axis.substr(0, 16)] = v.get<double>();
                }
            }
        }
    } else {  // progress
        if (!read_number(j, "fraction", probe.fraction) || !read_number(j, "eta_s", probe.eta_s))
            return false;
        probe.fraction = std::clamp(probe.fraction, -1.0, 1.0);
    }
    FleetMachine* m = machine_slot(name);
    if (!m) return false;
    *m = std::move(probe);
    return true;
}

bool FleetView::apply_job(const std::string& id, const std::string& leaf,
                          const std::string& payload) {
    if (payload.empty()) {
        if (leaf == "state") jobs_.erase(id);
        return true;
    }
    const Json j = object_of(payload);
    if (j.is_discarded() || j.is_null()) return false;
    FleetJob probe;
    if (const auto it = jobs_.find(id); it != jobs_.end()) probe = it->second;
    probe.id = id;
    if (leaf == "progress") {
        if (!read_number(j, "fraction", probe.fraction) || !read_number(j, "eta_s", probe.eta_s))
            return false;
        probe.fraction = std::clamp(probe.fraction, -1.0, 1.0);
        // Progress of a job never seen: keep it only if its state comes later (it holds no
        // state of its own, so it makes no job by itself).
        if (!jobs_.count(id)) return true;
    } else {
        std::string claimed;
        if (!read_text(j, "id", claimed) || (!claimed.empty() && claimed != id)) return false;
        const auto state = j.find("state");
        if (state == j.end() || !state->is_string() || !is_job_state(state->get<std::string>()))
            return false;
        probe.state = state->get<std::string>();
        probe.machine.clear();
        probe.error.clear();
        probe.at = 0;
        if (!read_text(j, "machine", probe.machine) || !read_text(j, "file", probe.file) ||
            !read_text(j, "error", probe.error) || !read_number(j, "at", probe.at))
            return false;
        probe.history.clear();
        if (const auto h = j.find("history"); h != j.end() && !h->is_null()) {
            if (!h->is_array()) return false;
            const std::size_t skip =
                h->size() > kFleetMaxHistory ? h->size() - kFleetMaxHistory : 0;
            for (std::size_t i = skip; i < h->size(); ++i) {
                const Json& e = (*h)[i];
                FleetJobStep step;
                if (!e.is_object() || !read_text(e, "state", step.state) ||
                    !read_text(e, "machine", step.machine) || !read_number(e, "at", step.at))
                    return false;
                probe.history.push_back(std::move(step));
            }
        }
    }
    FleetJob* slot = job_slot(id);
    if (!slot) return false;
    *slot = std::move(probe);
    return true;
}

std::vector<FleetMachine> FleetView::machines() const {
    std::vector<FleetMachine> out;
    out.reserve(machines_.size());
    for (const auto& [name, m] : machines_) out.push_back(m);
    // A machine's job: the latest active job state that names it. One pass over the jobs.
    std::map<std::string, const FleetJob*> current;
    for (const auto& [id, j] : jobs_) {
        if (!is_active(j.state) || j.machine.empty()) continue;
        const FleetJob*& c = current[j.machine];
        if (!c || j.at > c->at) c = &j;
    }
    for (FleetMachine& m : out) {
        const auto it = current.find(m.name);
        if (it != current.end()) m.job = it->second->id;
    }
    return out;
}

std::vector<FleetJob> FleetView::jobs() const {
    std::vector<FleetJob> out;
    out.reserve(jobs_.size());
    for (const auto& [id, j] : jobs_) out.push_back(j);
    std::stable_sort(out.begin(), out.end(),
                     [](const FleetJob& a, const FleetJob& b) { return a.at > b.at; });
    return out;
}

const FleetMachine* FleetView::machine(const std::string& name) const {
    const auto it = machines_.find(name);
    return it == machines_.end() ? nullptr : &it->second;
}

const FleetJob* FleetView::job(const std::string& id) const {
    const auto it = jobs_.find(id);
    return it == jobs_.end() ? nullptr : &it->second;
}

}  // namespace pathstream::host
