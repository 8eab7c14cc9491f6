#include "eval_command.hpp"

#include <cmath>
#include <iostream>
#include <optional>
#include <stdexcept>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/machine/atomic_file.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

void add_eval_command(CLI::App& app, EvalOptions& o) {
    CLI::App* cmd =
        app.add_subcommand("eval",
                           "Evaluate the path through the fixed-point core (Horner) at u = j/N, j "
                           "= 0..N-1, of every span, plus "
                           "each subpath's end point; CSV span,u,x,y,... in the path's units");
    add_path_options(*cmd, o.path);
    o.path.keep_order_by_default = true;  // the file's spans, in its order and direction
    cmd->add_option("--samples-per-span,-n", o.samples_per_span, "N: samples per span")
        ->capture_default_str()
        ->check(CLI::Range(1u, kMaxSpanTicks));
    cmd->add_option("--out,-o", o.output, "CSV output file; - or none: standard output");
    cmd->add_option("--lsb", o.mm_per_lsb, "millimetres per LSB")
        ->capture_default_str()
        ->check(CLI::Range(1e-6, 10.0));
    cmd->add_option("--machine,-m", o.machine,
                    "machine profile (JSON): takes the LSB size from it (instead of --lsb)")
        ->check(CLI::ExistingFile);
}

namespace {

/// Writes the rows: the core evaluates span k at tick j of N, which is exactly u = j / N.
std::size_t write_rows(const Path& path, const std::vector<CoreSpan>& spans, double mm_per_lsb,
                       std::uint32_t n, std::ostream& csv) {
    csv << "span,u";
    for (std::size_t a = 0; a < path.axes; ++a) csv << ',' << axis_column_name(a);
    csv << '\n';
    // One division per value, by the LSB count per unit (snapped to a whole number when it
    // is one, e.g. 25,400 LSB per inch at 1 um): the printed value is then the correctly
    // rounded quotient, and 25400 LSB prints as 1, not 1.0000000000000002.
    double lsb_per_unit = path.mm_per_unit / mm_per_lsb;
    if (std::fabs(lsb_per_unit - std::round(lsb_per_unit)) < 1e-9 * lsb_per_unit)
        lsb_per_unit = std::round(lsb_per_unit);
    std::size_t rows = 0, index = 0;
    const auto row = [&](const CoreSpan& span, std::uint32_t k) {
        csv << index << ',' << exact_decimal(static_cast<double>(k) / n);
        for (std::size_t a = 0; a < path.axes; ++a) {
            csv << ',' << exact_decimal(core_value_at(span, a, k) / lsb_per_unit);
        }
        csv << '\n';
        ++rows;
    };
    for (std::size_t i = 0; i < spans.size(); ++i) {
        if (!spans[i].pen_down) continue;  // travel between subpaths is not part of the path
        for (std::uint32_t k = 0; k < n; ++k) row(spans[i], k);
        const bool subpath_ends = i + 1 == spans.size() || !spans[i + 1].pen_down;
        if (subpath_ends) row(spans[i], n);
        ++index;
    }
    return rows;
}

}  // namespace

int run_eval(const EvalOptions& o) {
    const std::optional<MachineProfile> machine =
        o.machine.empty() ? std::nullopt
                          : std::optional<MachineProfile>(load_machine_profile(o.machine));
    const Path path = load_path(o.path, machine ? &*machine : nullptr);
    const double lsb = machine ? machine->mm_per_lsb : o.mm_per_lsb;
    const std::vector<CoreSpan> spans =
        uniform_core_spans(path, path_display_name(o.path.file), lsb, o.samples_per_span);
    std::size_t rows = 0;
    write_output(o.output, [&](std::ostream& csv) {
        rows = write_rows(path, spans, lsb, o.samples_per_span, csv);
    });
    std::cerr << "pathstream eval: " << path_display_name(o.path.file) << ": " << rows
              << " samples of " << path.subpaths.size() << " subpath(s) in " << path.units
              << ", exact to one LSB (" << lsb << " mm)"
              << (o.output.empty() || o.output == "-" ? "" : ", written to " + o.output) << '\n';
    return 0;
}

}  // namespace pathstream::host
