// `sim --mode AXIS:FREQ_HZ:DAMPING`: resonant modes from the command line, merged with the
// machine profile's "resonance" (docs/cli.md, `sim`).
#pragma once

#include <string>
#include <vector>

#include "pathstream/machine/machine.hpp"
#include "pathstream/sim/resonant_axis.hpp"

namespace pathstream::host {

/// One --mode: an axis name and its mode.
struct ModeOption {
    std::string axis;
    sim::ResonantMode mode;
};

/// Parses "AXIS:FREQ_HZ:DAMPING" (e.g. "x:40:0.05"): a non-empty axis name, a frequency in
/// Hz > 0, a damping ratio in (0, 1], both finite decimal numbers. Throws
/// std::invalid_argument "--mode TEXT: <what is wrong>", naming the bad part.
ModeOption parse_mode_option(const std::string& text);

/// The modes per axis of a run, in the profile's axis order: the profile's "resonance", each
/// axis that a --mode names taking the command line's modes (in their order) instead of the
/// profile's. Empty when neither gives one. Throws std::invalid_argument ("--mode TEXT: ...")
/// for an axis the profile lacks, a frequency at or above half the tick rate, or more than
/// kMaxResonanceModes modes for one axis.
std::vector<std::vector<sim::ResonantMode>> run_modes(const std::vector<std::string>& options,
                                                      const MachineProfile& profile);

/// "x: 40 Hz zeta 0.05; y: 40 Hz zeta 0.05, 120 Hz zeta 0.1": the modes for reports; "" without.
std::string describe_modes(const std::vector<std::vector<sim::ResonantMode>>& modes,
                           const MachineProfile& profile);

}  // namespace pathstream::host
