// The one error type of the host's input readers: a message that names the place.
#pragma once

#include <stdexcept>
#include <string>

#include "pathstream/host/path.hpp"

namespace pathstream::host {

/// Bad input. what() is "FILE:LINE:COL: message" (or "FILE: message" without a location).
class InputError : public std::runtime_error {
public:
    InputError(const std::string& file, SourceLocation at, const std::string& message)
        : std::runtime_error(format(file, at, message)) {}

private:
    static std::string format(const std::string& file, SourceLocation at, const std::string& m) {
        if (at.line == 0) return file + ": " + m;
        return file + ":" + std::to_string(at.line) + ":" + std::to_string(at.column) + ": " + m;
    }
};

}  // namespace pathstream::host
