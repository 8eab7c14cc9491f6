// bench_plan's peer table: one drawing planned by pathstream and by the grbl-style and
// Klipper-style reference planners (bench/reference_planners/) on the same machine limits, each
// peer on its own junction rule and held to the per-tick limits pathstream keeps, their motion
// times against pathstream's, and what the peers' profiles do at the device tick.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "pathstream/host/path.hpp"
#include "pathstream/machine/machine.hpp"
#include "reference_planners/tick_sampling.hpp"

namespace pathstream::bench {

/// One peer planner's figures on one drawing.
struct PeerFigures {
    double motion = 0;  ///< motion time, s (continuous, dwells excluded)
    TickFigures ticks;  ///< its profile sampled at the device tick
};

/// One drawing's figures.
struct PeerRow {
    std::string name;
    std::size_t segments = 0;       ///< Bezier segments pathstream plans
    std::size_t lines = 0;          ///< line moves the peers plan (flattened within the tolerance)
    double motion = 0;              ///< pathstream's motion time, s (whole ticks, dwells excluded)
    double optimum = 0;             ///< PlanStats::reference_motion_time, s (continuous TOPP-RA)
    double acceleration_exact = 0;  ///< pathstream's exact acceleration peak over the limit
    PeerFigures grbl, klipper;      ///< the peers on their own junction rules
    /// The peers held to the per-tick limits (JunctionRule::per_tick): no axis's velocity steps
    /// by more than one tick of its acceleration at a junction.
    PeerFigures grbl_held, klipper_held;
    /// Empty when pathstream's plan passed its check and all four peer plans are
    /// self-consistent (positive times, continuous speeds, at rest at stops and at the end, the
    /// sampled motion ending at the path's end) and the held ones keep every junction's velocity
    /// step within one tick of acceleration; else what failed.
    std::string problem;
};

/// Plans `path` with pathstream (default options; check_plan on every tick) and both peers,
/// each on its own junction rule and held (JunctionRule::per_tick).
/// Never throws: a failure becomes the row's problem.
PeerRow compare_with_peers(const std::string& name, const host::Path& path,
                           const host::MachineProfile& profile);

/// Prints the table (or a Markdown one) and the targets' tally (printed, never judged).
void print_peer_table(const std::vector<PeerRow>& rows, const host::MachineProfile& profile,
                      bool markdown);

}  // namespace pathstream::bench
