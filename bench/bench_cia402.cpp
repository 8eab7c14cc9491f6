// bench_cia402: the following error of CiA 402 cyclic synchronous position with and without
// feed-forward. Each example drawing, planned for the pen plotter, is driven through the CSP
// master over the in-process bus (tests/host/cia402_support.hpp: virtual clock, no wall time)
// to two simulated drives, at a 2 ms cycle, for servo natural frequencies of 50 Hz (the `sim`
// report's servo) and 100 Hz (the simulated drive's default), with feed-forward none,
// velocity (0x60B1) and velocity + torque (0x60B2). Prints the largest |demand - actual| of
// either drive in LSB and mm.
//   bench_cia402 [--quick] [--markdown] [--help]
// Target (independent of the machine's speed): velocity feed-forward cuts the largest following
// error at least tenfold on every drawing and bandwidth.
// Exit status (also printed by --help): 0 target met, 1 target missed, 2 usage error, 3 a
// drawing could not be planned or a run did not complete.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "bench_args.hpp"
#include "cia402_support.hpp"
#include "pathstream/host/cia402_master.hpp"
#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/svg_path.hpp"

using namespace pathstream;
using host::Cia402FeedForward;

namespace {

constexpr int kExitTargetMissed = 1, kExitRunFailed = 3;  // 2, a usage error: bench_args.hpp
// 300 per mille of rated torque at the pen plotter's 3000 mm/s^2 (3e6 LSB/s^2).
constexpr double kInertia = 1e-4;

constexpr const char* kUsageText =
    "usage: bench_cia402 [--quick] [--markdown] [--help]\n"
    "  Drives the example drawings (pen plotter, 2 ms cycle) through the CiA 402 master to two\n"
    "  simulated drives of 50 and 100 Hz and prints the largest following error without\n"
    "  feed-forward, with the velocity offset and with velocity and torque offsets.\n"
    "  --quick     examples/wave.json only (the ctest smoke run)\n"
    "  --markdown  the table in Markdown\n"
    "target (independent of the machine's speed): velocity feed-forward cuts the largest\n"
    "following error at least tenfold on every drawing and bandwidth.\n"
    "exit status: 0 target met; 1 target missed; 2 usage error; 3 a drawing could not be\n"
    "planned or a run did not complete.\n";

// Largest following error of either drive, LSB.
double run(const cia402_test::Job& job, double bandwidth_hz, Cia402FeedForward ff) {
    const std::vector<std::int32_t> first = cia402_test::cycle_setpoints(job.plan, 2, 2);
    sim::Cia402DriveOptions d;
    d.servo.bandwidth_hz = bandwidth_hz;
    d.torque_per_acceleration = kInertia;
    d.following_error_window = 1000000;  // measure, do not trip
    cia402_test::Rig rig(2, {first[0], first[1]}, 0, 1, d);
    host::Cia402Options o;
    o.nodes = {1, 2};
    o.cycle_ms = 2;
    o.feed_forward = ff;
    o.torque_per_acceleration = ff == Cia402FeedForward::kTorque ? kInertia : 0;
    o.settle_timeout_ms = 5000;
    host::stream_cia402(job.plan, job.machine, o, rig.master_bus, rig.hub.clock);
    double worst = 0;
    for (const auto& drive : rig.drives) worst = std::max(worst, drive->max_following_error());
    return worst;
}

host::Path load(const std::string& name) {
    const std::string file = std::string(PATHSTREAM_SOURCE_DIR) + "/examples/" + name;
    if (name.ends_with(".json")) return host::load_json_path(file);
    if (name.ends_with(".csv")) return host::load_csv_path(file, host::PathBasis::kPolyline, true);
    if (name.ends_with(".ngc")) return host::load_gcode_path(file);
    return host::load_svg_path(file);
}

}  // namespace

int main(int argc, char** argv) {
    bench::BenchArgs args;
    if (const auto exit = bench::parse_bench_args(argc, argv, kUsageText, args)) return *exit;
    const bool quick = args.quick, markdown = args.markdown;
    std::vector<std::string> names{"wave.json"};
    if (!quick) names.insert(names.end(), {"rose.json", "star.csv", "leaf.ngc", "landscape.svg"});
    const host::MachineProfile machine = host::load_machine_profile(
        std::string(PATHSTREAM_SOURCE_DIR) + "/examples/machines/pen_plotter.json");
    std::fputs(markdown ? "| drawing | servo | none | velocity | velocity + torque | ratio |\n"
                          "|---|---:|---:|---:|---:|---:|\n"
                        : "drawing         servo   none LSB (mm)      velocity LSB (mm)   "
                          "+ torque LSB (mm)   ratio\n",
               stdout);
    bool met = true;
    for (const std::string& name : names) {
        cia402_test::Job job;
        try {
            job.machine = machine;
            job.plan = host::plan_path(host::to_bezier_segments(load(name)), machine);
        } catch (const std::exception& e) {
            std::fprintf(stderr, "bench_cia402: %s: %s\n", name.c_str(), e.what());
            return kExitRunFailed;
        }
        for (const double hz : {50.0, 100.0}) {
            double e[3];
            try {
                e[0] = run(job, hz, Cia402FeedForward::kNone);
                e[1] = run(job, hz, Cia402FeedForward::kVelocity);
                e[2] = run(job, hz, Cia402FeedForward::kTorque);
            } catch (const std::exception& x) {
                std::fprintf(stderr, "bench_cia402: %s at %g Hz: %s\n", name.c_str(), hz, x.what());
                return kExitRunFailed;
            }
            const double ratio = e[0] / std::max(e[1], 1e-9);
            met = met && ratio >= 10;
            const double mm = machine.mm_per_lsb;
            if (markdown) {
                std::printf(
                    "| %s | %g Hz | %.0f LSB (%.3f mm) | %.1f LSB (%.4f mm) | %.1f LSB (%.4f "
                    "mm) | %.0fx |\n",
                    name.c_str(), hz, e[0], e[0] * mm, e[1], e[1] * mm, e[2], e[2] * mm, ratio);
            } else {
                std::printf("%-15s %3g Hz  %6.0f (%.3f)    %7.1f (%.4f)    %7.1f (%.4f)    %.0fx\n",
                            name.c_str(), hz, e[0], e[0] * mm, e[1], e[1] * mm, e[2], e[2] * mm,
                            ratio);
            }
        }
    }
    if (!met) std::fputs("target missed: velocity feed-forward below 10x somewhere\n", stdout);
    return met ? 0 : kExitTargetMissed;
}
