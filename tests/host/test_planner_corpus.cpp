// Every example (examples/*.json, *.svg, *.ngc, *.csv) and every test input under tests/data/
// that the readers accept plans on the pen plotter within its limits and the chord tolerance,
// checked tick by tick (check_plan); an input of three axes on the 3-axis router of
// tests/data/machines/ (whose machine profiles are not inputs). Files are found by listing the
// folders, not by name: a file a reader refuses is skipped by that verdict (and said so), and so is
// a job whose motion is estimated before planning (JobEstimate) at over kMotionBudget seconds,
// because the check costs time per tick: tests/data/gcode/arc_f1_medium.ngc and arc_f1_big.ngc, 1
// mm/min for 52 and 157 hours, are planned by their own hidden test (test_planner_slow_feed.cpp).
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstddef>
#include <exception>
#include <filesystem>
#include <string>
#include <vector>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/gcode_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/job_estimate.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/machine.hpp"

using namespace pathstream::host;
namespace fs = std::filesystem;

namespace {

/// Seconds of motion (estimated) above which a file is left out: about a second of checking
/// (arc_f1_small.ngc, 4,700 s, is in; under the sanitizers, several times slower, it is left to
/// test_planner_slow_feed.cpp).
#ifdef PATHSTREAM_SANITIZED
constexpr double kMotionBudget = 2000;
#else
constexpr double kMotionBudget = 10000;
#endif

std::string source_dir() {
#ifdef PATHSTREAM_SOURCE_DIR
    return PATHSTREAM_SOURCE_DIR;
#else
    return ".";
#endif
}

/// The files of `dir` (and of its subfolders with `recursive`) whose extension a reader
/// takes, in name order.
std::vector<fs::path> inputs(const fs::path& dir, bool recursive) {
    std::vector<fs::path> out;
    const auto take = [&](const fs::directory_entry& e) {
        static const std::vector<std::string> kExt = {".json", ".svg", ".ngc", ".gcode",
                                                      ".nc",   ".gc",  ".csv"};
        if (e.is_regular_file() && e.path().parent_path().filename() != "machines" &&
            std::find(kExt.begin(), kExt.end(), e.path().extension().string()) != kExt.end())
            out.push_back(e.path());
    };
    if (recursive) {
        for (const auto& e : fs::recursive_directory_iterator(dir)) take(e);
    } else {
        for (const auto& e : fs::directory_iterator(dir)) take(e);
    }
    std::sort(out.begin(), out.end());
    return out;
}

/// The file read as the CLI reads it by default (G-code with the pen chosen from the program,
/// --gcode-pen auto, so that a program without pen moves draws its feed moves).
Path read(const fs::path& file) {
    const std::string ext = file.extension().string(), name = file.string();
    if (ext == ".json") return load_json_path(name);
    if (ext == ".svg") return load_svg_path(name);
    if (ext == ".csv") return load_csv_path(name, PathBasis::kBSpline, false);
    GcodeOptions options;
    options.pen = PenControl::kAuto;
    return load_gcode_path(name, options);
}

struct Tally {
    std::size_t planned = 0, refused = 0, too_long = 0;
};

/// Reads, plans and checks every input of `dir`.
Tally plan_all(const fs::path& dir, bool recursive) {
    const MachineProfile plotter =
        load_machine_profile(source_dir() + "/examples/machines/pen_plotter.json");
    const MachineProfile router =
        load_machine_profile(source_dir() + "/tests/data/machines/router_3axis.json");
    Tally t;
    for (const fs::path& file : inputs(dir, recursive)) {
        const std::string name = fs::relative(file, source_dir()).string();
        Path path;
        try {
            path = read(file);
        } catch (const std::exception& e) {
            WARN(name << ": refused by the reader, skipped: " << e.what());
            ++t.refused;
            continue;
        }
        const MachineProfile& p = path.axes == router.axes.size() ? router : plotter;
        const auto segs = to_bezier_segments(path);
        const double estimate = JobEstimate(segs, p).model_seconds();
        if (estimate > kMotionBudget) {
            WARN(name << ": about " << estimate << " s of motion, left to its own test");
            ++t.too_long;
            continue;
        }
        INFO(name);
        const Plan plan = plan_path(segs, p);
        const PlanCheck c = check_plan(plan, segs, p);
        CHECK(plan.total_ticks > 0);
        CHECK(c.within_limits);
        CHECK_FALSE(c.drawing_while_pen_moves);
        CHECK(c.max_deviation <= p.chord_tolerance);
        ++t.planned;
    }
    return t;
}

}  // namespace

TEST_CASE("corpus: every example plans within the pen plotter's limits", "[planner][corpus]") {
    const Tally t = plan_all(source_dir() + "/examples", false);
    // rose.json, wave.json, landscape.svg, two_pens.svg, leaf.ngc, star.csv at least.
    CHECK(t.planned >= 6);
}

TEST_CASE("corpus: every test input the readers accept plans within the pen plotter's limits",
          "[planner][corpus]") {
    const Tally t = plan_all(source_dir() + "/tests/data", true);
    CHECK(t.planned >= 4);
}
