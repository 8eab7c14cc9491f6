// Planning for the input shaper (plan_for_shaper): the device's shaped command stays within the
// chord tolerance of the path, measured exactly from its integer setpoints; without it the
// same plan's shaped command leaves the path by far more.
#include <catch2/catch.hpp>
#include <string>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/machine/shaper_design.hpp"
#include "pathstream/sim/device.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

MachineProfile shaped_plotter(ShaperType type, bool plan_for_shaper) {
    MachineProfile m = load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) +
                                            "/examples/machines/pen_plotter.json");
    m.input_shaper.assign(m.axes.size(), ShaperSpec{type, 40, 0.05});
    m.plan_for_shaper = plan_for_shaper;
    return m;
}

struct Shaped {
    double deviation_mm = 0;
    std::uint64_t ticks = 0;
};

/// Plans `path` for `planning` and plays it on the ideal plant through `device`'s shapers.
Shaped shaped_run(const Path& path, const MachineProfile& planning, const MachineProfile& device) {
    const Plan plan = plan_path(to_bezier_segments(path), planning);
    sim::SimOptions o;
    o.record_ticks = false;
    for (const auto& spec : device.input_shaper)
        o.shaper.push_back(design_shaper_taps(*spec, device.tick_hz, kDeviceShaperHistoryTicks));
    const sim::SimulationResult r = sim::simulate(plan.spans, device, o);
    return {r.shaped_command.max_mm, plan.total_ticks};
}

}  // namespace

TEST_CASE("planned for the shaper, the shaped command stays within the chord tolerance",
          "[shaper][planner]") {
    const std::string examples = std::string(PATHSTREAM_SOURCE_DIR) + "/examples/";
    const Path wave = load_json_path(examples + "wave.json");
    const Path star = load_csv_path(examples + "star.csv", PathBasis::kPolyline, true);
    for (ShaperType type : {ShaperType::kMzv, ShaperType::kEi}) {
        const MachineProfile unplanned = shaped_plotter(type, false);
        const MachineProfile planned = shaped_plotter(type, true);
        for (const Path* path : {&wave, &star}) {
            CAPTURE(shaper_type_name(type), path == &wave ? "wave" : "star");
            const Shaped before = shaped_run(*path, unplanned, unplanned);
            const Shaped after = shaped_run(*path, planned, planned);
            CHECK(before.deviation_mm > 4 * unplanned.chord_tolerance);
            CHECK(after.deviation_mm <= planned.chord_tolerance);
            CHECK(after.ticks > before.ticks);  // the price: slower bends, rests at stops
        }
    }
}

TEST_CASE("planned for the shaper, a polyline's corners are turned exactly", "[shaper][planner]") {
    Path zigzag;
    zigzag.axes = 2;
    Subpath s;
    s.basis = PathBasis::kPolyline;
    s.points = PointList({{0, 0}, {10, 0}, {10, 10}, {20, 10}, {20, 20}});
    zigzag.subpaths.push_back(s);
    const MachineProfile planned = shaped_plotter(ShaperType::kZvd, true);
    // Every window of the shaped command holds points of one leg only: on the polyline, to
    // the half LSB the output is rounded to.
    CHECK(shaped_run(zigzag, planned, planned).deviation_mm <= 0.5 * planned.mm_per_lsb + 1e-12);
}
