// pathstream: the command-line tool. Exit codes (docs/cli.md): 0 success, 1 bad input file,
// 2 bad command line, 3 output could not be written, 4 internal error, 5 planning failed,
// 6 device or link failure (stream, device).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <iostream>
#include <stdexcept>
#include <system_error>

#include "cli/calibrate_command.hpp"
#include "cli/check_command.hpp"
#include "cli/ctl_command.hpp"
#include "cli/drive_command.hpp"
#include "cli/eval_command.hpp"
#include "cli/fleet_command.hpp"
#include "cli/plan_command.hpp"
#include "cli/serve_command.hpp"
#include "cli/setpoints_command.hpp"
#include "cli/sim_command.hpp"
#include "cli/stream_command.hpp"
#include "device_command.hpp"
#include "failure_exit.hpp"
#include "pathstream/hal/gpio_gpiod.hpp"
#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/exit_codes.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

int main(int argc, char** argv) {
    CLI::App app{"pathstream: exact spline paths to timed setpoints for plotters and servo axes"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "pathstream 0.1.0");
    pathstream::host::CheckOptions check;
    pathstream::host::add_check_command(app, check);
    pathstream::host::PlanCommandOptions plan;
    pathstream::host::add_plan_command(app, plan);
    pathstream::host::SimCommandOptions sim;
    pathstream::host::add_sim_command(app, sim);
    pathstream::host::SetpointsOptions setpoints;
    pathstream::host::add_setpoints_command(app, setpoints);
    pathstream::host::EvalOptions eval;
    pathstream::host::add_eval_command(app, eval);
    pathstream::host::StreamCommandOptions stream;
    pathstream::host::add_stream_command(app, stream);
    pathstream::device_cli::DeviceCommandOptions device;
    pathstream::device_cli::add_device_command(app, device);
    pathstream::host::DriveCommandOptions drive;
    pathstream::host::add_drive_command(app, drive);
    pathstream::host::CtlCommandOptions ctl;
    pathstream::host::add_ctl_command(app, ctl);
    pathstream::host::ServeCommandOptions serve;
    pathstream::host::add_serve_command(app, serve);
    pathstream::host::CalibrateOptions calibrate;
    pathstream::host::add_calibrate_command(app, calibrate);
    pathstream::host::FleetCommandOptions fleet;
    pathstream::host::add_fleet_command(app, fleet);

    return pathstream::device_cli::parse_and_run(app, argc, argv, [&]() -> int {
        try {
            if (app.got_subcommand("setpoints")) return pathstream::host::run_setpoints(setpoints);
            if (app.got_subcommand("eval")) return pathstream::host::run_eval(eval);
            if (app.got_subcommand("check")) return pathstream::host::run_check(check);
            if (app.got_subcommand("plan")) return pathstream::host::run_plan(plan);
            if (app.got_subcommand("sim")) return pathstream::host::run_sim(sim);
            if (app.got_subcommand("stream")) return pathstream::host::run_stream(stream);
            if (app.got_subcommand("device")) return pathstream::device_cli::run_device(device);
            if (app.got_subcommand("drive")) return pathstream::host::run_drive(drive);
            if (app.got_subcommand("ctl")) return pathstream::host::run_ctl(ctl);
            if (app.got_subcommand("serve")) return pathstream::host::run_serve(serve);
            if (app.got_subcommand("calibrate")) return pathstream::host::run_calibrate(calibrate);
            if (app.got_subcommand("fleet")) return pathstream::host::run_fleet(fleet);
        } catch (const pathstream::host::PlanError& e) {
            std::cerr << "pathstream: planning failed: " << e.what() << '\n';
            return kExitPlanning;
        } catch (const pathstream::host::StreamError& e) {
            std::cerr << "pathstream: device: " << e.what() << '\n';
            return kExitDevice;
        }
        return kExitInternal;
    });
}
