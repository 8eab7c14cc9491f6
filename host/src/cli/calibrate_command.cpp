#include "calibrate_command.hpp"

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>

#include "mode_option.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/ring_down.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/machine/shaper_design.hpp"
#include "pathstream/sim/device.hpp"

namespace pathstream::host {

void add_calibrate_command(CLI::App& app, CalibrateOptions& o) {
    CLI::App* cmd = app.add_subcommand(
        "calibrate",
        "Measure an axis's resonance from a ring-down (on the simulated machine, or a recorded "
        "CSV) and propose the input shaper for it (docs/input-shaping.md)");
    cmd->add_option("--machine,-m", o.machine, "machine profile (JSON, docs/formats.md)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--axis", o.axes,
                    "axis to calibrate (repeatable; default: every axis the simulated machine "
                    "has modes on; exactly one with --csv)");
    cmd->add_option("--mode", o.modes,
                    "a resonant mode of the simulated machine, AXIS:FREQ_HZ:DAMPING as sim takes "
                    "it (over the profile's \"resonance\")");
    cmd->add_option("--bandwidth", o.bandwidth_hz, "the simulated servo's bandwidth, Hz")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 10000.0));
    cmd->add_option("--damping", o.damping, "the simulated servo's damping ratio")
        ->capture_default_str()
        ->check(CLI::Range(0.05, 20.0));
    cmd->add_option("--distance", o.distance, "mm the test move travels on the axis")
        ->capture_default_str()
        ->check(CLI::Range(0.01, 10000.0));
    cmd->add_option("--csv", o.csv,
                    "a recorded ring-down instead of the simulated one: columns time (s) and "
                    "position (mm) or acceleration (mm/s^2)")
        ->check(CLI::ExistingFile);
    cmd->add_flag("--json", o.json, "print the result as one JSON document");
}

namespace {

using Json = nlohmann::ordered_json;

/// Ring-down of `axis` on the simulated machine: a move of `distance` mm on it alone, planned
/// at the profile's limits, then the tool's position once the servo has settled.
RingDownSamples simulated_ring_down(const CalibrateOptions& o, const MachineProfile& profile,
                                    std::size_t axis,
                                    const std::vector<std::vector<sim::ResonantMode>>& modes) {
    PathPoint from(profile.axes.size(), 0.0);
    for (std::size_t a = 0; a < profile.axes.size(); ++a) {
        const AxisLimits& l = profile.axes[a];
        if (l.has_travel) from[a] = (l.travel_min + l.travel_max) / 2;
    }
    PathPoint to = from;
    const AxisLimits& l = profile.axes[axis];
    to[axis] += l.has_travel ? std::min(o.distance, (l.travel_max - l.travel_min) / 4) : o.distance;
    Path path;
    path.axes = profile.axes.size();
    Subpath move;
    move.basis = PathBasis::kPolyline;
    move.points = PointList({from, to});
    path.subpaths.push_back(move);
    const Plan plan = plan_path(to_bezier_segments(path), profile);
    sim::SimOptions s;
    s.plant = sim::PlantModel::kServo;
    s.servo.bandwidth_hz = o.bandwidth_hz;
    s.servo.damping = o.damping;
    s.modes = modes;
    s.settle_ticks = static_cast<std::uint64_t>(profile.tick_hz);  // 1 s of ringing
    const sim::SimulationResult r = sim::simulate(plan.spans, profile, s);
    // From the last tick the command changed, plus the servo's settling.
    std::uint64_t last_move = 0;
    for (std::uint64_t k = 1; k < r.ticks; ++k)
        if (r.setpoint(k, axis) != r.setpoint(k - 1, axis)) last_move = k;
    const std::uint64_t from_tick =
        last_move + sim::servo_settle_ticks(profile.tick_hz, o.bandwidth_hz, o.damping);
    RingDownSamples samples;
    for (std::uint64_t k = from_tick; k < r.ticks; ++k) {
        samples.time.push_back(static_cast<double>(k) / profile.tick_hz);
        samples.value.push_back(r.position(k, axis));
    }
    return samples;
}

/// Each family tuned to `fit`: its residual there and the worst over +-10 % and +-20 %.
struct Proposal {
    ShaperType type;
    double residual = 0, worst_10 = 0, worst_20 = 0, duration = 0;
};

std::vector<Proposal> proposals(const RingDown& fit, double tick_hz) {
    std::vector<Proposal> out;
    for (ShaperType type : {ShaperType::kZv, ShaperType::kMzv, ShaperType::kZvd, ShaperType::kEi,
                            ShaperType::kTwoHumpEi, ShaperType::kThreeHumpEi}) {
        const auto taps = design_shaper_taps({type, fit.frequency_hz, fit.damping}, tick_hz,
                                             kDeviceShaperHistoryTicks);
        Proposal p{type};
        p.residual = residual_vibration_ratio(taps, tick_hz, fit.frequency_hz, fit.damping);
        for (double off : {0.8, 0.9, 0.95, 1.05, 1.1, 1.2}) {
            const double v =
                residual_vibration_ratio(taps, tick_hz, fit.frequency_hz * off, fit.damping);
            if (off >= 0.9 && off <= 1.1) p.worst_10 = std::max(p.worst_10, v);
            p.worst_20 = std::max(p.worst_20, v);
        }
        p.duration = shaper_duration(taps, tick_hz);
        out.push_back(p);
    }
    return out;
}

/// The shortest family that keeps the vibration within 5 % over +-10 % of the measured
/// frequency (what a ring-down's estimate and a machine's drift leave uncertain).
const Proposal& recommended(const std::vector<Proposal>& ps) {
    const Proposal* best = nullptr;
    for (const Proposal& p : ps)
        if (p.worst_10 <= 0.05 && (best == nullptr || p.duration < best->duration)) best = &p;
    return best != nullptr ? *best : ps.back();
}

}  // namespace

int run_calibrate(const CalibrateOptions& o) {
    const MachineProfile profile = load_machine_profile(o.machine);
    std::vector<std::size_t> axes;
    for (const std::string& name : o.axes) {
        std::size_t a = 0;
        while (a < profile.axes.size() && profile.axes[a].name != name) ++a;
        if (a == profile.axes.size())
            throw std::invalid_argument("--axis " + name + ": not an axis of " + o.machine);
        axes.push_back(a);
    }
    const auto modes = run_modes(o.modes, profile);
    if (!o.csv.empty()) {
        if (axes.size() != 1)
            throw std::invalid_argument("--csv: name the axis it was recorded on with one --axis");
    } else if (axes.empty()) {
        for (std::size_t a = 0; a < modes.size(); ++a)
            if (!modes[a].empty()) axes.push_back(a);
        if (axes.empty()) {
            throw std::invalid_argument(
                "the simulated machine has no resonant modes to measure: give --mode AXIS:FREQ:"
                "DAMPING or the profile's \"resonance\" (or --csv with a recorded ring-down)");
        }
    }
    Json j;
    Json shaper_snippet = Json::object();
    for (std::size_t axis : axes) {
        const std::string& name = profile.axes[axis].name;
        const RingDownSamples samples = o.csv.empty() ? simulated_ring_down(o, profile, axis, modes)
                                                      : load_ring_down_csv(o.csv);
        RingDown fit;
        try {
            fit = fit_ring_down(samples);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("axis " + name + ": " + e.what());
        }
        const std::vector<Proposal> ps = proposals(fit, profile.tick_hz);
        const Proposal& pick = recommended(ps);
        Json a;
        a["source"] = o.csv.empty() ? "simulated ring-down" : o.csv;
        a["frequency_hz"] = fit.frequency_hz;
        a["damping"] = fit.damping;
        a["half_cycles"] = fit.half_cycles;
        Json list = Json::array();
        for (const Proposal& p : ps) {
            list.push_back({{"type", shaper_type_name(p.type)},
                            {"residual", p.residual},
                            {"worst_within_10_percent", p.worst_10},
                            {"worst_within_20_percent", p.worst_20},
                            {"duration_s", p.duration}});
        }
        a["shapers"] = list;
        a["recommended"] = shaper_type_name(pick.type);
        j["axes"][name] = a;
        shaper_snippet[name] = {{"type", shaper_type_name(pick.type)},
                                {"frequency", std::round(fit.frequency_hz * 100) / 100},
                                {"damping", std::round(fit.damping * 1000) / 1000}};
        if (!o.json) {
            std::printf("%s: %s: %.2f Hz, damping ratio %.4f (%zu half-cycles)\n", name.c_str(),
                        o.csv.empty() ? "simulated ring-down" : o.csv.c_str(), fit.frequency_hz,
                        fit.damping, fit.half_cycles);
            std::printf(
                "  shaper     vibration left: tuned  within +-10 %%  within +-20 %%  "
                "duration\n");
            for (const Proposal& p : ps) {
                std::printf("  %-9s %20.2f %% %12.2f %% %14.2f %% %7.1f ms%s\n",
                            shaper_type_name(p.type), 100 * p.residual, 100 * p.worst_10,
                            100 * p.worst_20, 1000 * p.duration,
                            &p == &pick ? "  <- proposed" : "");
            }
        }
    }
    j["input_shaper"] = shaper_snippet;
    if (o.json) {
        std::cout << j.dump(2) << '\n';
    } else {
        std::cout << "for the profile (docs/formats.md):\n  \"input_shaper\": "
                  << shaper_snippet.dump() << '\n';
    }
    return 0;
}

}  // namespace pathstream::host
