// pathstream-device: the device runtime alone, as a machine's controller runs it. The same
// command as `pathstream device`, built without the host's planner, readers and plots.
#include <CLI/CLI.hpp>

#include "device_command.hpp"
#include "failure_exit.hpp"

int main(int argc, char** argv) {
    CLI::App app{"pathstream-device: the device runtime (docs/cli.md, \"device\")"};
    app.set_version_flag("--version", "pathstream-device 0.1.0");
    pathstream::device_cli::DeviceCommandOptions options;
    pathstream::device_cli::add_device_command(app, options);
    app.require_subcommand(1);
    return pathstream::device_cli::parse_and_run(
        app, argc, argv, [&] { return pathstream::device_cli::run_device(options); });
}
