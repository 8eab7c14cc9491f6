// `pathstream stream`: plan a path and stream it to a device over Modbus (docs/modbus.md).
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "path_options.hpp"
#include "pathstream/host/modbus_stream.hpp"
#include "pathstream/machine/exit_codes.hpp"

namespace pathstream::host {

struct StreamCommandOptions {
    JobRequest path;
    std::string machine;
    StreamOptions stream;
    /// A pen-up move from where the device rests to the drawing's start is planned by default
    /// (Modbus and native CAN); --no-lead-in refuses a device resting elsewhere instead.
    /// --lead-in (the default) is kept for scripts; CiA 402 targets refuse it.
    bool lead_in = false;
    bool no_lead_in = false;
    std::string
        journal;  ///< job journal path ("" : DRAWING-STEM.journal.json in the current directory)
    bool no_journal = false;
    bool replace_journal =
        false;           ///< --replace-journal: an unfinished job's journal may be replaced
    std::string resume;  ///< continue the job of this journal
    double hold_timeout_seconds = 10;  ///< Ctrl-C: a hold not at rest by then becomes a stop
    std::string events;                ///< --events: NDJSON events to this file ("-": stdout)
    double events_rate = 5;            ///< --events-rate: progress events per second, at most
    /// --plan-first: plan the whole job before anything is sent (the events' totals known
    /// from job_start; memory grows with the job), instead of streaming while planning.
    bool plan_first = false;
    std::string mqtt;  ///< --mqtt: report to this broker and take operator commands from it
    std::string name;  ///< --name: the machine's name on the broker
};

void add_stream_command(CLI::App& app, StreamCommandOptions& options);
int run_stream(const StreamCommandOptions& options);

}  // namespace pathstream::host
