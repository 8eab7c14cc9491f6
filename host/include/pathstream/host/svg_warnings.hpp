// What the SVG reader does not draw, told once per kind: a file with 10,000 <text> elements
// gets one warning with the count and the first place, not 10,000 lines.
#pragma once

#include <cstddef>
#include <string>
#include <unordered_map>
#include <vector>

#include "pathstream/host/path.hpp"

namespace pathstream::host::svg {

/// Warnings grouped by their message, in the order each message first occurred.
class WarningLog {
public:
    /// Records one occurrence of `message` (without a place) at `at`.
    void add(const std::string& message, SourceLocation at);
    /// One line per message: "file:line:col: message" at its first place, and when it occurred
    /// more than once "(N times; the first here)".
    std::vector<std::string> lines(const std::string& file) const;
    /// Occurrences recorded of `message` (0 when none).
    std::size_t count(const std::string& message) const;

private:
    struct Entry {
        std::string message;
        SourceLocation first;
        std::size_t count = 0;
    };
    std::vector<Entry> entries_;
    std::unordered_map<std::string, std::size_t> index_;  // message -> entry
};

}  // namespace pathstream::host::svg
