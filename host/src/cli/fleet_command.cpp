#include "fleet_command.hpp"

#include <cmath>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <optional>
#include <stdexcept>
#include <thread>

#include "fleet_actions.hpp"
#include "pathstream/host/fleet_view.hpp"

namespace pathstream::host {

void add_fleet_command(CLI::App& app, FleetCommandOptions& o) {
    CLI::App* fleet = app.add_subcommand(
        "fleet",
        "Watch the machines and jobs on an MQTT broker, submit jobs to its queues, "
        "command one machine, serve the fleet page (docs/mqtt.md)");
    o.command = fleet;
    fleet->require_subcommand(1);
    fleet
        ->add_option("--mqtt", o.mqtt,
                     "the broker: mqtt[s]://[USER[:PASSWORD]@]HOST[:PORT]"
                     "[?cafile=..&password_file=..] (as serve --mqtt)")
        ->required();
    fleet->add_option("--settle", o.settle, "s to wait for the retained state after subscribing")
        ->capture_default_str()
        ->check(CLI::Range(0.05, 60.0));

    CLI::App* status =
        fleet->add_subcommand("status", "the machines: online, state, job, progress");
    status->add_flag("--json", o.json, "print JSON instead of a table");
    CLI::App* jobs = fleet->add_subcommand("jobs", "the jobs and their history");
    jobs->add_flag("--json", o.json, "print JSON instead of a table");

    CLI::App* submit = fleet->add_subcommand("submit", "publish a job; print its id");
    submit->add_option("file", o.file, "the drawing (.json .csv .svg .ngc .gcode .nc .bpt)")
        ->required()
        ->check(CLI::ExistingFile);
    auto* kind = submit->add_option("--kind", o.kind,
                                    "the queue: any idle machine of this kind (default: any)");
    submit->add_option("--machine", o.machine, "this machine only")->excludes(kind);
    submit->add_option("--id", o.id,
                       "the job's id: 1 to 64 of A-Z a-z 0-9 _ - (default: generated)");
    submit->add_option("--fit", o.fit,
                       "place it on this paper (a4, a3, letter, ...) or the work area (area)");
    submit->add_option("--margin", o.margin, "mm kept from the paper's edges")
        ->check(CLI::Range(0.0, 1000.0));
    submit->add_flag("--wait", o.wait, "wait for a final state; exit 0 only when done");
    submit->add_option("--max-upload-mb", o.max_upload_mb, "largest drawing sent, MB")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 1024.0));

    CLI::App* command =
        fleet->add_subcommand("command", "one command to one machine; print its reply");
    command->add_option("name", o.name, "the machine")->required();
    command
        ->add_option("verb", o.verb,
                     "hold, resume, stop, reset, home, pen, jog, resume_job, drop_job")
        ->required();
    command->add_option("--axis", o.axis, "jog: the axis");
    command->add_option("--distance", o.distance, "jog: mm, signed");
    command->add_option("--pen", o.pen, "pen: up or down")->check(CLI::IsMember({"up", "down"}));
    command->add_option("--timeout", o.timeout, "s to wait for the reply")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 3600.0));

    CLI::App* serve = fleet->add_subcommand("serve", "serve the fleet page");
    serve
        ->add_option("--listen", o.listen,
                     "HOST:PORT; beyond loopback needs --token or --token-file")
        ->capture_default_str();
    serve->add_option("--token", o.token, "a secret every request must carry");
    serve->add_option("--token-file", o.token_file, "the token from this file's first line")
        ->check(CLI::ExistingFile);
    serve->add_option("--max-upload-mb", o.max_upload_mb, "largest drawing accepted, MB")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 1024.0));
    // Options of `fleet` (--mqtt, --settle) may also come after the subcommand.
    for (CLI::App* sub : {status, jobs, submit, command, serve}) sub->fallthrough();
}

namespace {

std::string percent(double fraction) {
    if (fraction < 0) return "-";
    char text[16];
    std::snprintf(text, sizeof text, "%.0f %%", std::floor(fraction * 100));
    return text;
}

std::string utc_time(double at) {
    if (at <= 0) return "-";
    const std::time_t t = static_cast<std::time_t>(at);
    std::tm utc{};
    ::gmtime_r(&t, &utc);
    char text[32];
    std::strftime(text, sizeof text, "%Y-%m-%d %H:%M:%S", &utc);
    return text;
}

// Rows printed as columns as wide as their widest cell (two spaces apart).
void print_table(const std::vector<std::vector<std::string>>& rows) {
    std::vector<std::size_t> width;
    for (const auto& r : rows) {
        width.resize(std::max(width.size(), r.size()));
        for (std::size_t i = 0; i < r.size(); ++i) width[i] = std::max(width[i], r[i].size());
    }
    for (const auto& r : rows) {
        std::string line;
        for (std::size_t i = 0; i < r.size(); ++i) {
            line += r[i];
            if (i + 1 < r.size()) line += std::string(width[i] - r[i].size() + 2, ' ');
        }
        while (!line.empty() && line.back() == ' ') line.pop_back();  // an empty last cell
        std::cout << line << '\n';
    }
}

int print_status(const FleetLink& link, bool json) {
    std::vector<FleetMachine> machines;
    std::uint64_t ignored = 0;
    link.read([&](const FleetView& v) {
        machines = v.machines();
        ignored = v.ignored();
    });
    if (json) {
        nlohmann::json out = nlohmann::json::array();
        for (const FleetMachine& m : machines) out.push_back(to_json(m));
        std::cout << nlohmann::json{{"machines", out}, {"ignored", ignored}}.dump() << '\n';
        return 0;
    }
    std::vector<std::vector<std::string>> rows{{"NAME", "ONLINE", "STATE", "JOB", "PROGRESS"}};
    for (const FleetMachine& m : machines) {
        rows.push_back({m.name, m.online ? "yes" : "no",
                        m.error.empty() ? (m.state.empty() ? "-" : m.state) : "error",
                        m.job.empty() ? "-" : m.job, m.job.empty() ? "-" : percent(m.fraction)});
    }
    print_table(rows);
    std::cout << machines.size() << " machines";
    if (ignored) std::cout << ", " << ignored << " malformed messages ignored";
    std::cout << '\n';
    return 0;
}

int print_jobs(const FleetLink& link, bool json) {
    std::vector<FleetJob> jobs;
    link.read([&](const FleetView& v) { jobs = v.jobs(); });
    if (json) {
        nlohmann::json out = nlohmann::json::array();
        for (const FleetJob& j : jobs) out.push_back(to_json(j));
        std::cout << nlohmann::json{{"jobs", out}}.dump() << '\n';
        return 0;
    }
    std::vector<std::vector<std::string>> rows{
        {"ID", "STATE", "MACHINE", "FILE", "AT (UTC)", "ERROR"}};
    for (const FleetJob& j : jobs) {
        rows.push_back(
            {j.id, j.state, j.machine.empty() ? "-" : j.machine, j.file, utc_time(j.at), j.error});
    }
    print_table(rows);
    for (const FleetJob& j : jobs) {
        std::string steps;
        for (const FleetJobStep& s : j.history) {
            steps += (steps.empty() ? "" : ", ") + s.state;
            if (!s.machine.empty()) steps += " on " + s.machine;
            steps += " " + utc_time(s.at).substr(11);
        }
        std::cout << j.id << ": " << (steps.empty() ? "no history" : steps) << '\n';
    }
    std::cout << jobs.size() << " jobs\n";
    return 0;
}

}  // namespace

int run_fleet(const FleetCommandOptions& o) {
    const CLI::App& f = *o.command;
    // Every value is checked before connecting: a bad one is exit 2 whatever the broker does.
    FleetLink link(parse_mqtt_url(o.mqtt));
    std::optional<FleetJobMessages> job;
    if (f.got_subcommand("submit")) job = prepare_fleet_job(o);
    if (f.got_subcommand("command")) check_command(o);
    link.connect();
    const auto settle = std::chrono::milliseconds(static_cast<long>(o.settle * 1000));
    int status = 0;
    if (f.got_subcommand("status") || f.got_subcommand("jobs")) {
        // The broker sends the retained topics right after each grant: a short wait has them
        // all (a quiet moment would never come from machines that report 10 times a second).
        std::this_thread::sleep_for(settle);
        status = f.got_subcommand("status") ? print_status(link, o.json) : print_jobs(link, o.json);
    } else if (job) {
        status = run_fleet_submit(link, o, *job);
    } else if (f.got_subcommand("command")) {
        status = run_fleet_command(link, o);
    } else if (f.got_subcommand("serve")) {
        status = run_fleet_serve(link, o);
    }
    link.disconnect();
    return status;
}

}  // namespace pathstream::host
