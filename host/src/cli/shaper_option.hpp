// `sim --shaper AXIS:TYPE:FREQ_HZ[:DAMPING]`: the device's input shapers from the command line,
// merged with the machine profile's "input_shaper" (docs/cli.md, `sim`; docs/input-shaping.md).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "pathstream/machine/machine.hpp"
#include "pathstream/machine/shaper_design.hpp"
#include "pathstream/shaper_taps.hpp"

namespace pathstream::host {

/// One --shaper: an axis name and its shaper, none for "AXIS:none", or every axis unshaped for
/// "none" (axis empty).
struct ShaperOption {
    std::string axis;
    std::optional<ShaperSpec> spec;
};

/// Parses "AXIS:TYPE:FREQ_HZ[:DAMPING]" (e.g. "x:mzv:40", "y:ei:36:0.05"), "AXIS:none" or
/// "none": a non-empty axis name, a type of shaper_type_names(), a frequency > 0 Hz and a
/// damping ratio in [0, 1) (default 0.1), finite decimal numbers. Throws
/// std::invalid_argument "--shaper TEXT: <what is wrong>", naming the bad part.
ShaperOption parse_shaper_option(const std::string& text);

/// The shapers per axis of a run, in the profile's axis order: the profile's
/// "input_shaper", then each --shaper in order ("none" clears every axis). Throws
/// std::invalid_argument ("--shaper TEXT: ...") for an axis the profile lacks.
std::vector<std::optional<ShaperSpec>> run_shapers(const std::vector<std::string>& options,
                                                   const MachineProfile& profile);

/// Each axis's taps at the profile's tick rate (empty: unshaped). Throws
/// std::invalid_argument ("input shaper of x: ...") when design_shaper_taps refuses one.
std::vector<std::vector<ShaperTap>> shaper_taps(const std::vector<std::optional<ShaperSpec>>& specs,
                                                const MachineProfile& profile);

/// "x: mzv 40 Hz zeta 0.1, 5 taps over 19 ms; y: ...": the shapers for reports; "" without.
std::string describe_shapers(const std::vector<std::optional<ShaperSpec>>& specs,
                             const std::vector<std::vector<ShaperTap>>& taps,
                             const MachineProfile& profile);

}  // namespace pathstream::host
