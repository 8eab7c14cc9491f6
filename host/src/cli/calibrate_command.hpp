// `pathstream calibrate`: an axis's resonance from a ring-down on the simulated machine or from
// a recorded CSV, and the input shaper it calls for (docs/input-shaping.md, "Calibration").
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

namespace pathstream::host {

struct CalibrateOptions {
    std::string machine;             ///< -m: the profile
    std::vector<std::string> axes;   ///< --axis NAME, repeatable; empty: every axis with modes
    std::vector<std::string> modes;  ///< --mode AXIS:FREQ_HZ:DAMPING, as sim's
    double bandwidth_hz = 50;        ///< the simulated servo
    double damping = 1.0;
    double distance = 10;  ///< mm the test move travels
    std::string csv;       ///< --csv FILE: a recorded ring-down instead
    bool json = false;
};

void add_calibrate_command(CLI::App& app, CalibrateOptions& options);
/// Runs it; returns the exit code. Throws std::invalid_argument / InputError with the reason.
int run_calibrate(const CalibrateOptions& options);

}  // namespace pathstream::host
