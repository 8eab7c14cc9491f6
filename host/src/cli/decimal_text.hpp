// A whole command-line part read as a finite decimal number, for options made of several parts
// (sim --mode, sim --shaper).
#pragma once

#include <optional>
#include <string>

namespace pathstream::host {

/// `part` as a finite decimal number when all of it is one (strtod's syntax), else nothing.
std::optional<double> decimal_text(const std::string& part);

}  // namespace pathstream::host
