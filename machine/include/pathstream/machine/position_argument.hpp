// A position a person types: mm ("139.322"), or LSB with the suffix "lsb" ("139322lsb").
#pragma once

#include <string>

#include "pathstream/units.hpp"

namespace pathstream::host {

/// `text` as a whole number of LSB at `mm_per_lsb` mm each, within the core's position range.
/// `what` names the option in messages ("--position"). Throws std::invalid_argument (exit 2)
/// for anything else: not a number, not a whole LSB, out of range.
Lsb parse_position_argument(const std::string& text, double mm_per_lsb, const std::string& what);

/// Whether `text` carries the LSB suffix (and so needs no mm scale).
bool is_lsb_argument(const std::string& text);

}  // namespace pathstream::host
