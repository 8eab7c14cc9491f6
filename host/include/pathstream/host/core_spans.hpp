// Turns a geometric path into the core's spans: coordinates quantised to LSB, open ends
// clamped, subpaths joined by straight pen-up travel, every span validated by the core.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "pathstream/host/path.hpp"
#include "pathstream/machine/core_span.hpp"

namespace pathstream::host {

/// Spans of `path` at a uniform `ticks_per_span`, quantised at `mm_per_lsb`.
/// Throws InputError naming `file` and the subpath when a point or a span is outside what the
/// core accepts (the core's own validation decides, with its status text).
std::vector<CoreSpan> uniform_core_spans(const Path& path, const std::string& file,
                                         double mm_per_lsb, std::uint32_t ticks_per_span);

}  // namespace pathstream::host
