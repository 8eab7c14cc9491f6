// pathstream: the command-line tool. Exit codes (docs/cli.md): 0 success, 1 bad input file,
// 2 bad command line, 3 output could not be written, 4 internal error.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <iostream>

#include "pathstream/host/input_error.hpp"
#include "cli/eval_command.hpp"
#include "cli/setpoints_command.hpp"

namespace {
constexpr int kExitInput = 1;
constexpr int kExitUsage = 2;
constexpr int kExitOutput = 3;
constexpr int kExitInternal = 4;
}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"pathstream: exact spline paths to timed setpoints for plotters and servo axes"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "pathstream 0.1.0");
    pathstream::host::SetpointsOptions setpoints;
    pathstream::host::add_setpoints_command(app, setpoints);
    pathstream::host::EvalOptions eval;
    pathstream::host::add_eval_command(app, eval);

    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        app.exit(e);
        return kExitUsage;
    }

    try {
        if (app.got_subcommand("setpoints")) return pathstream::host::run_setpoints(setpoints);
        if (app.got_subcommand("eval")) return pathstream::host::run_eval(eval);
    } catch (const pathstream::host::InputError& e) {
        std::cerr << e.what() << '\n';
        return kExitInput;
    } catch (const std::runtime_error& e) {
        std::cerr << "pathstream: " << e.what() << '\n';
        return kExitOutput;
    } catch (const std::exception& e) {
        std::cerr << "pathstream: internal error: " << e.what() << '\n';
        return kExitInternal;
    }
    return kExitInternal;
}
