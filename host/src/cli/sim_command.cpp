#include "sim_command.hpp"

#include <filesystem>
#include <iostream>

#include "plan_command.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/plot.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/sim/device.hpp"

namespace pathstream::host {

void add_sim_command(CLI::App& app, SimCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "sim", "Plan the path and run it on the simulated plotter (the firmware core on a simulated HAL): "
               "plots and a one-screen report");
    add_path_options(*cmd, o.path);
    cmd->add_option("--machine,-m", o.machine, "machine profile (JSON, docs/formats.md)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--plot", o.plot_dir, "directory for path/speed/acceleration plots (SVG, and PNG with rsvg-convert)");
    cmd->add_flag("--realtime", o.realtime, "pace the device at its real tick rate (default: as fast as possible)");
    cmd->add_option("--plant", o.plant, "axis model: ideal (position = setpoint) or servo (2nd order)")
        ->capture_default_str()
        ->check(CLI::IsMember({"ideal", "servo"}));
    cmd->add_option("--bandwidth", o.bandwidth_hz, "servo bandwidth, Hz")->capture_default_str()->check(CLI::Range(0.1, 10000.0));
    cmd->add_option("--damping", o.damping, "servo damping ratio")->capture_default_str()->check(CLI::Range(0.05, 20.0));
    cmd->add_flag("--y-up", o.y_up, "draw path.svg with +y upwards (default: downwards, like SVG and most plotters)");
}

int run_sim(const SimCommandOptions& o) {
    const PlannedJob job = plan_job(o.path, o.machine);

    sim::SimOptions options;
    options.plant = o.plant == "ideal" ? sim::PlantModel::kIdeal : sim::PlantModel::kServo;
    options.servo.bandwidth_hz = o.bandwidth_hz;
    options.servo.damping = o.damping;
    options.realtime = o.realtime;
    sim::SimulationResult result;
    {
        ProgressBar bar(o.realtime ? "running (real time)" : "simulating");
        result = sim::simulate(job.plan, job.machine, options, [&](double f) { bar.update(f); });
    }
    const plot::TickSeries executed = sim::setpoint_series(result);
    const plot::TickSeries plant = sim::plant_series(result);

    std::cout << plot::text_report(job.plan, &job.check, job.machine, executed, sim::run_summary(result));
    if (!o.plot_dir.empty()) {
        std::filesystem::create_directories(o.plot_dir);
        plot::Options plot_options;
        plot_options.y_up = o.y_up;
        plot_options.title = o.path.file;
        const plot::WrittenPlots written = plot::write_plots(
            o.plot_dir, job.segments, executed, options.plant == sim::PlantModel::kServo ? &plant : nullptr,
            job.machine, plot_options);
        std::cout << "plots:";
        for (const auto& f : written.files) std::cout << ' ' << f;
        std::cout << '\n';
        if (!written.note.empty()) std::cout << "note: " << written.note << '\n';
    }
    if (result.underruns != 0) {
        std::cerr << "pathstream: the device ran dry " << result.underruns << " times (a streaming bug)\n";
        return 4;
    }
    if (!job.check.within_limits || job.check.drawing_while_pen_moves) {
        throw PlanError("the plan failed its per-tick check (a planner bug): see the report above");
    }
    return 0;
}

}  // namespace pathstream::host
