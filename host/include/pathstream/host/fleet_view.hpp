// What a watcher of the broker knows about the fleet: the machines (from their retained
// online, status and progress topics) and the jobs (from their retained state and progress),
// folded from the messages one at a time (docs/mqtt.md, "pathstream fleet").
#pragma once

#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace pathstream::host {

/// At most this many machines and jobs are kept: a broker anyone may publish to must not make
/// a watcher grow without end. A new machine past the cap is ignored; a new job past it takes
/// the place of the oldest finished one (or is ignored when none has finished).
inline constexpr std::size_t kFleetMaxMachines = 4096;
inline constexpr std::size_t kFleetMaxJobs = 4096;
/// Larger payloads are not parsed (a job state with a long history stays far below).
inline constexpr std::size_t kFleetMaxPayload = 256 * 1024;
/// The newest history entries a job keeps.
inline constexpr std::size_t kFleetMaxHistory = 64;

/// One machine as its topics describe it (pathstream/NAME/...).
struct FleetMachine {
    std::string name;
    bool online = false;
    std::string machine_file;       ///< the profile's file name, from `online`
    std::vector<std::string> axes;  ///< from `online`
    std::string kind;               ///< from `online` when the machine says it, else ""
    std::string state;              ///< the device's state from `status` ("idle", "running")
    std::string error;              ///< the device's error from `status`, "" for none
    std::map<std::string, double> position_mm;  ///< from `status`
    double fraction = -1;                       ///< the job's progress, 0 .. 1; -1: none known
    double eta_s = -1;                          ///< s of motion left; -1: none known
    std::string job;  ///< the job it runs, holds or was interrupted in; "" none
};

/// One entry of a job's history.
struct FleetJobStep {
    std::string state;
    std::string machine;  ///< "" for none (queued)
    double at = 0;        ///< s since 1970
};

/// One job as its retained state says (pathstream/jobs/ID/state).
struct FleetJob {
    std::string id;
    std::string state;
    std::string machine;
    std::string file;
    double at = 0;
    std::string error;
    std::vector<FleetJobStep> history;  ///< oldest first, the newest kFleetMaxHistory
    double fraction = -1;               ///< from pathstream/jobs/ID/progress; -1: none
    double eta_s = -1;
};

/// True for a state no job leaves: done, failed, stopped, refused, dropped.
bool is_final_job_state(const std::string& state);

/// True for 1 to 64 of A-Z a-z 0-9 _ - (a machine name or a job id: each is a topic level).
bool is_fleet_name(const std::string& text);

/// The fleet as the messages seen so far describe it. Not thread-safe: one owner (the caller
/// locks). Every call is bounded: a payload over kFleetMaxPayload is not parsed.
class FleetView {
public:
    /// Folds one message. Returns false (and counts it in ignored()) for a topic of ours whose
    /// payload makes no sense: not JSON, not an object, fields of the wrong type, a state that
    /// does not exist, a name that cannot be a topic level, too large. Topics the view does
    /// not describe (commands, replies, events, job messages) are skipped, not counted.
    bool apply(const std::string& topic, const std::string& payload);

    /// The machines by name, each with its current job (from the jobs' states).
    std::vector<FleetMachine> machines() const;
    /// The jobs, newest state first.
    std::vector<FleetJob> jobs() const;
    /// The job `id`, or null.
    const FleetJob* job(const std::string& id) const;
    /// The machine `name` as last seen (online or not; its `job` not filled in), or null.
    const FleetMachine* machine(const std::string& name) const;

    /// Messages ignored as malformed or past a cap, since construction.
    std::uint64_t ignored() const { return ignored_; }
    /// Messages folded, since construction.
    std::uint64_t applied() const { return applied_; }

    /// Everything as JSON: {"machines": [...], "jobs": [...], "ignored": N} (the fleet
    /// server's GET /api/fleet and `fleet status --json`).
    nlohmann::json to_json() const;

private:
    bool apply_machine(const std::string& name, const std::string& leaf,
                       const std::string& payload);
    bool apply_job(const std::string& id, const std::string& leaf, const std::string& payload);
    FleetMachine* machine_slot(const std::string& name);
    FleetJob* job_slot(const std::string& id);

    std::map<std::string, FleetMachine> machines_;
    std::map<std::string, FleetJob> jobs_;
    std::uint64_t ignored_ = 0;
    std::uint64_t applied_ = 0;
};

/// A machine as JSON (name, online, machine, axes, kind, state, error, position_mm, fraction,
/// eta_s, job; unknown numbers are null).
nlohmann::json to_json(const FleetMachine& machine);
/// A job as JSON (id, state, machine, file, at, error, history, fraction, eta_s).
nlohmann::json to_json(const FleetJob& job);

}  // namespace pathstream::host
