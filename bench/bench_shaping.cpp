// bench_shaping: input shaping on the simulated machine. Each drawing, planned for the pen
// plotter, runs on the simulated device with the 50 Hz servo driving resonant modes on x and y
// (one mode of 40 Hz, zeta 0.05; and that mode with a second of 95 Hz, zeta 0.08), unshaped and
// with each shaper family tuned to 40 Hz, then with the shaper 20 % off the mode (the mode at
// 32 and at 48 Hz). Per run: residual vibration (the tool's ringing after the stops, largest)
// and the ratio unshaped / shaped, contour error, the time shaping adds, the shaped command's
// own distance from the path (the ideal plant: what the shaper cuts off corners, from the
// exact integer setpoints), and the limit check of every shaped tick against the unshaped;
// then the path planned for the shaper (plan_for_shaper): the motion time it adds and the shaped
// command's exact distance from the path, which must stay within the chord tolerance.
//   bench_shaping [--quick] [--markdown] [--help]
// Targets (independent of the machine's speed): with the mode at the tuned frequency MZV cuts
// the residual vibration at least 20x (EI is designed to leave its 5 % tolerance there: 20x at
// best, printed, not held); with the mode 20 % off the EI family at least 5x; no shaped tick moves
// faster than the fastest unshaped tick or accelerates harder than the hardest unshaped one plus
// the one LSB/tick^2 of rounding (docs/input-shaping.md); planned for the shaper, every shaped
// command stays within the chord tolerance of the path. Exit status (also printed by --help): 0
// targets met, 1 a target missed, 2 usage error, 3 a drawing could not be planned or run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "bench_args.hpp"
#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/machine/shaper_design.hpp"
#include "pathstream/sim/device.hpp"

using namespace pathstream;
using host::ShaperType;

namespace {

constexpr int kExitTargetMissed = 1, kExitRunFailed = 3;  // 2, a usage error: bench_args.hpp
constexpr double kModeHz = 40, kModeDamping = 0.05;

constexpr const char* kUsageText =
    "usage: bench_shaping [--quick] [--markdown] [--help]\n"
    "  Runs the example drawings and two corner-heavy polylines on the simulated pen plotter\n"
    "  (50 Hz servo, a 40 Hz zeta 0.05 mode on x and y; then with a second mode of 95 Hz)\n"
    "  unshaped and with each input shaper tuned to 40 Hz, and with the mode 20 % off the\n"
    "  shaper, and prints residual vibration, contour error, time cost, the shaped command's\n"
    "  distance from the path and the limit check.\n"
    "  --quick     examples/wave.json and the zigzag, one mode (the ctest smoke run)\n"
    "  --markdown  the tables in Markdown\n"
    "targets (independent of the machine's speed): MZV cuts the residual vibration at least\n"
    "20x at the tuned frequency; the EI family at least 5x with the mode 20 % off; no\n"
    "shaped tick exceeds the unshaped run's velocity, nor its acceleration by more than the\n"
    "one LSB/tick^2 of rounding; planned for the shaper (plan_for_shaper), the shaped command\n"
    "stays within the chord tolerance of the path.\n"
    "exit status: 0 targets met; 1 a target missed; 2 usage error; 3 a drawing could not be\n"
    "planned or run.\n";

/// A corner-heavy polyline as a CSV file in the temporary directory: `kind` "zigzag" (right
/// angles, 10 mm legs) or "spikes" (160-degree turns, 20 mm legs).
std::string corner_file(const std::string& kind) {
    const auto file =
        std::filesystem::temp_directory_path() / ("pathstream_bench_" + kind + ".csv");
    std::ofstream out(file);
    out << "x,y\n";
    for (int i = 0; i <= 16; ++i) {
        if (kind == "zigzag")
            out << 10.0 * ((i + 1) / 2) << "," << 10.0 * (i / 2) << "\n";
        else
            out << 10.0 * i << "," << (i % 2 == 0 ? 0.0 : 20.0) << "\n";
    }
    return file.string();
}

host::Path load(const std::string& name) {
    if (name == "zigzag" || name == "spikes")
        return host::load_csv_path(corner_file(name), host::PathBasis::kPolyline, false);
    const std::string file = std::string(PATHSTREAM_SOURCE_DIR) + "/examples/" + name;
    if (name.ends_with(".json")) return host::load_json_path(file);
    if (name.ends_with(".csv")) return host::load_csv_path(file, host::PathBasis::kPolyline, true);
    return host::load_gcode_path(file);
}

/// What one run gives.
struct Figures {
    double residual_um = 0;
    double contour_um = 0;
    std::uint64_t ticks = 0;
    std::int64_t peak_step = 0;    // largest |setpoint difference| over both axes, LSB/tick
    std::int64_t peak_second = 0;  // largest |second difference|, LSB/tick^2
};

Figures figures_of(const sim::SimulationResult& r) {
    Figures f;
    f.residual_um = r.residual.max_mm * 1000;
    f.contour_um = r.contour.max_mm * 1000;
    f.ticks = r.ticks;
    for (std::size_t a = 0; a < r.axes; ++a) {
        for (std::uint64_t k = 2; k < r.ticks; ++k) {
            const std::int64_t x0 = r.setpoint(k - 2, a), x1 = r.setpoint(k - 1, a),
                               x2 = r.setpoint(k, a);
            f.peak_step = std::max<std::int64_t>(f.peak_step, std::abs(x2 - x1));
            f.peak_second = std::max<std::int64_t>(f.peak_second, std::abs(x2 - 2 * x1 + x0));
        }
    }
    return f;
}

/// One run: the plant with `modes` on x and y, the device shaping with `shaper` (none: empty).
Figures run(const std::vector<host::CoreSpan>& spans, const host::MachineProfile& machine,
            const std::vector<sim::ResonantMode>& modes, std::optional<host::ShaperSpec> shaper,
            bool ideal = false) {
    sim::SimOptions o;
    o.plant = ideal ? sim::PlantModel::kIdeal : sim::PlantModel::kServo;
    if (!ideal) o.modes = {modes, modes};
    double lowest = o.servo.bandwidth_hz;
    for (const auto& m : modes) lowest = std::min(lowest, m.frequency_hz);
    o.settle_ticks =
        sim::residual_window_ticks(machine.tick_hz, lowest) +
        sim::servo_settle_ticks(machine.tick_hz, o.servo.bandwidth_hz, o.servo.damping);
    if (shaper) {
        const auto taps =
            host::design_shaper_taps(*shaper, machine.tick_hz, host::kDeviceShaperHistoryTicks);
        o.shaper = {taps, taps};
    }
    return figures_of(sim::simulate(spans, machine, o));
}

struct Row {
    std::string path;
    std::string shaper;
    double residual_um = 0, ratio = 0, worst_off_ratio = 0, contour_um = 0;
    double added_ms = 0, command_um = 0;
    // Planned for the shaper (plan_for_shaper): the motion time added, in per cent of the
    // unshaped plan's, and the shaped command's distance from the path.
    double planned_added_percent = 0, planned_command_um = 0;
    bool limits_ok = true;
};

}  // namespace

int main(int argc, char** argv) {
    bench::BenchArgs args;
    if (const auto exit = bench::parse_bench_args(argc, argv, kUsageText, args)) return *exit;
    const bool quick = args.quick, markdown = args.markdown;
    std::vector<std::string> names{"wave.json", "zigzag"};
    if (!quick) names.insert(names.end(), {"rose.json", "star.csv", "leaf.ngc", "spikes"});
    const host::MachineProfile machine = host::load_machine_profile(
        std::string(PATHSTREAM_SOURCE_DIR) + "/examples/machines/pen_plotter.json");
    const ShaperType types[] = {ShaperType::kZv, ShaperType::kZvd,       ShaperType::kMzv,
                                ShaperType::kEi, ShaperType::kTwoHumpEi, ShaperType::kThreeHumpEi};
    struct Plant {
        const char* name;
        std::vector<sim::ResonantMode> modes;
    };
    std::vector<Plant> plants{{"40 Hz", {{kModeHz, kModeDamping}}}};
    if (!quick) plants.push_back({"40 + 95 Hz", {{kModeHz, kModeDamping}, {95, 0.08}}});

    bool met = true;
    for (const Plant& plant : plants) {
        std::printf(markdown ? "\n**Plant: 50 Hz servo, modes %s on x and y**\n\n"
                             : "\nplant: 50 Hz servo, modes %s on x and y\n",
                    plant.name);
        std::fputs(markdown ? "| path | shaper | residual um | cut | cut, mode 20 % off | "
                              "contour um | time added ms | command off path um | planned for "
                              "it: time | planned: off path um | limits |\n"
                              "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---|\n"
                            : "path        shaper     residual um    cut  cut 20% off  contour um"
                              "  +ms  command um  planned   off um  limits\n",
                   stdout);
        for (const std::string& name : names) {
            std::vector<host::CoreSpan> spans;
            try {
                spans = host::plan_path(host::to_bezier_segments(load(name)), machine).spans;
            } catch (const std::exception& e) {
                std::fprintf(stderr, "bench_shaping: %s: %s\n", name.c_str(), e.what());
                return kExitRunFailed;
            }
            std::vector<Row> rows;
            try {
                const Figures none = run(spans, machine, plant.modes, std::nullopt);
                // The mode 20 % off the shaper: the same runs with the plant's first mode moved.
                std::vector<sim::ResonantMode> low = plant.modes, high = plant.modes;
                low[0].frequency_hz *= 0.8;
                high[0].frequency_hz *= 1.2;
                const Figures none_low = run(spans, machine, low, std::nullopt);
                const Figures none_high = run(spans, machine, high, std::nullopt);
                Row unshaped;
                unshaped.path = name;
                unshaped.shaper = "none";
                unshaped.residual_um = none.residual_um;
                unshaped.ratio = unshaped.worst_off_ratio = 1;
                unshaped.contour_um = none.contour_um;
                rows.push_back(unshaped);
                for (ShaperType type : types) {
                    const host::ShaperSpec spec{type, kModeHz, kModeDamping};
                    const Figures f = run(spans, machine, plant.modes, spec);
                    const Figures f_low = run(spans, machine, low, spec);
                    const Figures f_high = run(spans, machine, high, spec);
                    const Figures command = run(spans, machine, {}, spec, true);
                    const Figures plain = run(spans, machine, {}, std::nullopt, true);
                    Row r;
                    r.path = name;
                    r.shaper = host::shaper_type_name(type);
                    r.residual_um = f.residual_um;
                    r.ratio = none.residual_um / std::max(f.residual_um, 1e-9);
                    r.worst_off_ratio =
                        std::min(none_low.residual_um / std::max(f_low.residual_um, 1e-9),
                                 none_high.residual_um / std::max(f_high.residual_um, 1e-9));
                    r.contour_um = f.contour_um;
                    r.added_ms = static_cast<double>(f.ticks - none.ticks) / machine.tick_hz * 1000;
                    r.command_um = command.contour_um;
                    host::MachineProfile planned_machine = machine;
                    planned_machine.input_shaper.assign(machine.axes.size(), spec);
                    planned_machine.plan_for_shaper = true;
                    const std::vector<host::CoreSpan> planned_spans =
                        host::plan_path(host::to_bezier_segments(load(name)), planned_machine)
                            .spans;
                    const Figures planned = run(planned_spans, machine, {}, spec, true);
                    r.planned_added_percent =
                        100.0 *
                        (static_cast<double>(planned.ticks) - static_cast<double>(plain.ticks)) /
                        static_cast<double>(plain.ticks);
                    r.planned_command_um = planned.contour_um;
                    r.limits_ok = command.peak_step <= plain.peak_step &&
                                  command.peak_second <= plain.peak_second + 1;
                    rows.push_back(r);
                    // 20x at the tuned frequency is MZV's goal: EI is designed to leave its 5 %
                    // tolerance there (a 20x cut at best), and is held to the off-tune goal.
                    const bool tuned_class = type == ShaperType::kMzv;
                    const bool ei_class = type == ShaperType::kEi ||
                                          type == ShaperType::kTwoHumpEi ||
                                          type == ShaperType::kThreeHumpEi;
                    const bool planned_ok = r.planned_command_um <= machine.chord_tolerance * 1000;
                    if (!r.limits_ok || !planned_ok || (tuned_class && r.ratio < 20) ||
                        (ei_class && r.worst_off_ratio < 5)) {
                        // The goals are set for the single mode the shaper is tuned to.
                        if (plant.modes.size() == 1 || !r.limits_ok || !planned_ok) met = false;
                    }
                }
            } catch (const std::exception& e) {
                std::fprintf(stderr, "bench_shaping: %s: %s\n", name.c_str(), e.what());
                return kExitRunFailed;
            }
            for (const Row& r : rows) {
                if (markdown) {
                    std::printf(
                        "| %s | %s | %.2f | %.1fx | %.1fx | %.1f | %.0f | %.1f | %+.1f %% | %.2f | "
                        "%s |\n",
                        r.path.c_str(), r.shaper.c_str(), r.residual_um, r.ratio, r.worst_off_ratio,
                        r.contour_um, r.added_ms, r.command_um, r.planned_added_percent,
                        r.planned_command_um, r.limits_ok ? "ok" : "EXCEEDED");
                } else {
                    std::printf(
                        "%-11s %-9s %10.2f %7.1fx %9.1fx %11.1f %5.0f %10.1f %+8.1f%% %9.2f  %s\n",
                        r.path.c_str(), r.shaper.c_str(), r.residual_um, r.ratio, r.worst_off_ratio,
                        r.contour_um, r.added_ms, r.command_um, r.planned_added_percent,
                        r.planned_command_um, r.limits_ok ? "ok" : "EXCEEDED");
                }
            }
        }
    }
    std::printf(
        "\ntargets: MZV cuts >= 20x tuned, the EI family >= 5x 20 %% off (one mode); "
        "limits on every shaped tick; planned for the shaper, within the chord tolerance: %s\n",
        met ? "met" : "MISSED");
    return met ? 0 : kExitTargetMissed;
}
