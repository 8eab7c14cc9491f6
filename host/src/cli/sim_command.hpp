// `pathstream sim`: plan and run the plan on the simulated plotter; plots and a report. The
// plan is made as the device runs it and the report and plots come from a record of bounded
// size, unless --plan-first (the whole plan, then every tick kept).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "path_options.hpp"

namespace pathstream::host {

struct SimCommandOptions {
    JobRequest path;
    std::string machine;
    std::string plot_dir;
    bool realtime = false;
    std::string plant = "servo";
    double bandwidth_hz = 50;
    double damping = 1.0;
    std::vector<std::string> modes;    ///< --mode AXIS:FREQ_HZ:DAMPING, repeatable
    std::vector<std::string> shapers;  ///< --shaper AXIS:TYPE:FREQ_HZ[:DAMPING], repeatable
    bool y_up = false;
    bool json = false;        ///< --json: one JSON document on standard output instead of text
    std::string events;       ///< --events: NDJSON events to this file ("-": stdout)
    double events_rate = 5;   ///< --events-rate: progress events per simulated second, at most
    bool plan_first = false;  ///< --plan-first: plan it all, keep every tick
};

void add_sim_command(CLI::App& app, SimCommandOptions& options);
int run_sim(const SimCommandOptions& options);

}  // namespace pathstream::host
