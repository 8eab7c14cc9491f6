// The one error type of the host's input readers: a message that names the place.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>

#include "pathstream/machine/source_location.hpp"

namespace pathstream::host {

/// Bad input. what() is "FILE:LINE:COL: message" (or "FILE: message" without a location).
/// A message that quotes the input is cut to its first 600 and last 200 bytes, with how many
/// were left out between: a 1 MB number made a 1 MB message.
class InputError : public std::runtime_error {
public:
    InputError(const std::string& file, SourceLocation at, const std::string& message)
        : std::runtime_error(format(file, at, bounded(message))) {}

    static constexpr std::size_t kMaxMessage = 1000;

private:
    static std::string bounded(const std::string& m) {
        if (m.size() <= kMaxMessage) return m;
        return m.substr(0, 600) + " ... (" + std::to_string(m.size() - 800) +
               " bytes left out) ... " + m.substr(m.size() - 200);
    }
    static std::string format(const std::string& file, SourceLocation at, const std::string& m) {
        if (at.line == 0) return file + ": " + m;
        return file + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) + ": " + m;
    }
};

}  // namespace pathstream::host
