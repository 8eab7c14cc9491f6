#include "setpoints_command.hpp"

#include <chrono>
#include <cmath>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "path_options.hpp"
#include "pathstream/host/core_playback.hpp"
#include "pathstream/host/core_spans.hpp"
#include "pathstream/machine/atomic_file.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {
namespace {

struct RunSummary {
    std::uint64_t ticks = 0;
    std::size_t spans = 0;
    std::uint64_t verified = 0;
};

/// One CSV row per executed tick (play_through_core checks each against Horner).
RunSummary write_setpoints(const Path& path, const std::vector<CoreSpan>& spans,
                           std::ostream& csv) {
    csv << "tick,span,subpath,pen";
    for (std::size_t a = 0; a < path.axes; ++a) csv << ',' << axis_column_name(a);
    csv << '\n';
    RunSummary summary;
    summary.spans = spans.size();
    summary.ticks = play_through_core(spans, path.axes, [&](const PlayedTick& t) {
        csv << t.tick << ',' << t.span << ',' << spans[t.span].subpath << ','
            << (t.pen_down ? 1 : 0);
        for (std::size_t a = 0; a < path.axes; ++a) csv << ',' << t.setpoint[a];
        csv << '\n';
        summary.verified += path.axes;
    });
    return summary;
}

}  // namespace

void add_setpoints_command(CLI::App& app, SetpointsOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "setpoints",
        "Run a path through the firmware core (exact forward differencing) and write every "
        "tick's setpoints as CSV: tick,span,subpath,pen,x,y,... in LSB");
    add_path_options(*cmd, o.path);
    o.path.keep_order_by_default = true;  // the file's spans, in its order and direction
    cmd->add_option("--out,-o", o.output, "CSV output file; - or none: standard output");
    cmd->add_option("--ticks-per-span", o.ticks_per_span,
                    "ticks each span lasts (default 32, or the profile's)")
        ->check(CLI::Range(1u, kMaxSpanTicks));
    cmd->add_option("--lsb", o.mm_per_lsb, "millimetres per LSB (default 0.001, or the profile's)")
        ->check(CLI::Range(1e-6, 10.0));
    cmd->add_option("--machine,-m", o.machine,
                    "machine profile (JSON): its mm_per_lsb and ticks_per_span, its work area for "
                    "--fit area")
        ->check(CLI::ExistingFile);
}

int run_setpoints(const SetpointsOptions& o) {
    const auto t0 = std::chrono::steady_clock::now();
    const std::optional<MachineProfile> machine =
        o.machine.empty() ? std::nullopt
                          : std::optional<MachineProfile>(load_machine_profile(o.machine));
    const Path path = load_path(o.path, machine ? &*machine : nullptr);
    const double lsb = o.mm_per_lsb ? *o.mm_per_lsb : machine ? machine->mm_per_lsb : 0.001;
    const std::uint32_t ticks = o.ticks_per_span ? *o.ticks_per_span
                                : machine        ? machine->ticks_per_span
                                                 : 32;
    const std::vector<CoreSpan> spans =
        uniform_core_spans(path, path_display_name(o.path.file), lsb, ticks);
    RunSummary summary;
    write_output(o.output, [&](std::ostream& csv) { summary = write_setpoints(path, spans, csv); });
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::cerr << "pathstream setpoints: " << path_display_name(o.path.file) << ": "
              << path.subpaths.size() << " subpath(s), " << summary.spans << " spans x " << ticks
              << " ticks, " << path.axes << " axes -> " << summary.ticks << " ticks"
              << (o.output.empty() || o.output == "-" ? "" : " written to " + o.output) << "\n"
              << "  every setpoint (" << summary.verified
              << ") equals the core's 128-bit Horner value: exact, rounded once; " << ms << " ms\n";
    return 0;
}

}  // namespace pathstream::host
