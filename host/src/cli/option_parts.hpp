// The parts of command-line options made of several (sim --mode, sim --shaper): a decimal
// number, an axis of the machine profile by name.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// `part` as a finite decimal number when all of it is one (strtod's syntax), else nothing.
std::optional<double> decimal_text(const std::string& part);

/// The index of the profile's axis called `name`. Throws std::invalid_argument ("axis \"z\" is
/// not in the machine profile (axes: x, y)") when it has none.
std::size_t profile_axis(const MachineProfile& profile, const std::string& name);

}  // namespace pathstream::host
