// `fleet submit` and `fleet command`: what a submitter and an operator publish, and what they
// wait for.
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <thread>

#include "fleet_actions.hpp"
#include "pathstream/host/fleet_job.hpp"

namespace pathstream::host {

namespace {

double unix_now() {
    return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
        .count();
}

}  // namespace

std::string machine_refusal(const FleetLink& link, const std::string& name) {
    bool known = false, online = false;
    link.read([&](const FleetView& v) {
        if (const FleetMachine* m = v.machine(name)) {
            known = true;
            online = m->online;
        }
    });
    if (!known) return "no machine named " + name + " on the broker";
    // A machine stopped properly has ended its broker session, which drops what is sent to it;
    // one whose host died gets it only when it comes back. Neither is a job drawn now.
    if (!online) return "machine " + name + " is offline: a job sent to it now would not be drawn";
    return "";
}

std::string read_job_file(const std::string& path, std::size_t max_bytes) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::invalid_argument("cannot read " + path);
    std::string text(max_bytes + 1, '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (text.size() > max_bytes) {
        throw std::invalid_argument(path + ": larger than --max-upload-mb (" +
                                    std::to_string(max_bytes) + " bytes)");
    }
    return text;
}

FleetJobMessages prepare_fleet_job(const FleetCommandOptions& o) {
    FleetJobSpec spec;
    spec.file_name = o.file;
    spec.max_bytes = static_cast<std::size_t>(o.max_upload_mb * 1024 * 1024);
    spec.drawing = read_job_file(o.file, spec.max_bytes);
    spec.kind = o.kind;
    spec.machine = o.machine;
    spec.id = o.id;
    if (!o.fit.empty()) spec.options["fit"] = o.fit;
    if (o.margin >= 0) spec.options["margin"] = o.margin;
    std::random_device entropy;
    std::mt19937_64 random(entropy());
    return build_fleet_job(spec, unix_now(), random);
}

void check_command(const FleetCommandOptions& o) {
    if (!is_fleet_name(o.name)) {
        throw std::invalid_argument("machine \"" + o.name +
                                    "\": 1 to 64 of A-Z a-z 0-9 _ - (it is part of topics)");
    }
}

int run_fleet_submit(FleetLink& link, const FleetCommandOptions& o, const FleetJobMessages& job) {
    if (!o.machine.empty()) {
        // A job on the topic of a machine nobody runs would wait for nobody: refuse it.
        std::this_thread::sleep_for(std::chrono::milliseconds(static_cast<long>(o.settle * 1000)));
        const std::string why = machine_refusal(link, o.machine);
        if (!why.empty()) throw std::invalid_argument(why);
    }
    // The state first: a watcher sees the job queued before any machine can take it.
    link.publish(job.state_topic, job.state.dump(), 1, true);
    link.publish(job.topic, job.message.dump(), 1, false);
    std::cout << job.id << '\n' << std::flush;
    if (!o.wait) return 0;

    const bool terminal = ::isatty(STDERR_FILENO) != 0;
    std::string state, last_line;
    for (;;) {
        // Woken by a new state, or every 250 ms for the progress on a terminal.
        link.wait_for(
            [&](const FleetView& v) {
                const FleetJob* j = v.job(job.id);
                return j && j->state != state;
            },
            std::chrono::milliseconds(250));
        FleetJob seen;
        link.read([&](const FleetView& v) {
            if (const FleetJob* j = v.job(job.id)) seen = *j;
        });
        if (seen.state.empty()) continue;
        if (terminal) {
            char line[160];
            std::snprintf(line, sizeof line, "\r%s %s%s%s %3.0f %%", job.id.c_str(),
                          seen.state.c_str(), seen.machine.empty() ? "" : " on ",
                          seen.machine.c_str(), seen.fraction < 0 ? 0.0 : seen.fraction * 100);
            if (line != last_line) std::cerr << line << std::flush;
            last_line = line;
        } else if (seen.state != state) {
            std::cerr << job.id << " " << seen.state
                      << (seen.machine.empty() ? "" : " on " + seen.machine) << '\n';
        }
        state = seen.state;
        if (is_final_job_state(state)) {
            if (terminal) std::cerr << '\n';
            if (state == "done") return 0;
            std::cerr << "pathstream: job " << job.id << " " << state
                      << (seen.machine.empty() ? "" : " on " + seen.machine)
                      << (seen.error.empty() ? "" : ": " + seen.error) << '\n';
            return 1;
        }
    }
}

int run_fleet_command(FleetLink& link, const FleetCommandOptions& o) {
    nlohmann::json request{{"verb", o.verb}};
    if (!o.axis.empty()) request["axis"] = o.axis;
    if (o.distance != 0) request["distance_mm"] = o.distance;
    if (!o.pen.empty()) request["down"] = o.pen == "down";
    const auto timeout = std::chrono::milliseconds(static_cast<long>(o.timeout * 1000));
    const std::optional<nlohmann::json> reply = link.command(o.name, request, timeout);
    if (!reply) {
        std::cerr << "pathstream: machine " << o.name << " did not answer within " << o.timeout
                  << " s (is it online? pathstream fleet status)\n";
        return 6;
    }
    std::cout << reply->dump() << '\n';
    const nlohmann::json status = reply->value("status", nlohmann::json());
    if (status.is_number_integer() && status.get<int>() == 200) return 0;
    std::cerr << "pathstream: machine " << o.name << " answered "
              << (status.is_number() ? status.dump() : "without a status") << ": "
              << (reply->contains("error") && (*reply)["error"].is_string()
                      ? (*reply)["error"].get<std::string>()
                      : std::string("no reason given"))
              << '\n';
    return 6;
}

}  // namespace pathstream::host
