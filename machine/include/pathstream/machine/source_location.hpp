// Where a value came from in its input file, for error messages (file:line:col).
#pragma once

#include <cstddef>

namespace pathstream::host {

/// Where a value came from in its input file (1-based; 0: unknown).
struct SourceLocation {
    std::size_t line = 0;
    std::size_t column = 0;
};

}  // namespace pathstream::host
