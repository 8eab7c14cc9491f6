// Shared by the fuzz targets: the properties every reader must keep, checked with abort() so
// libFuzzer records the input that broke them.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "pathstream/host/path.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::fuzz {

// Stops the run on a broken property, printing why.
[[noreturn]] inline void violated(const std::string& what) {
    std::fprintf(stderr, "property violated: %s\n", what.c_str());
    std::abort();
}

// Geometry a reader may return: 1..8 axes, every point with that many finite coordinates.
inline void check_path(const host::Path& p) {
    if (p.axes < 1 || p.axes > 8) violated("axes " + std::to_string(p.axes));
    for (const host::Subpath& s : p.subpaths) {
        if (s.points.empty()) violated("a subpath without points");
        for (const host::PathPoint& point : s.points) {
            if (point.size() != p.axes) violated("a point with the wrong number of coordinates");
            for (const double c : point) {
                if (!std::isfinite(c)) violated("a coordinate that is not finite");
            }
        }
    }
}

// Runs `read` (returning a Path): geometry, or an InputError naming `file` first; nothing else.
template <typename Read>
void check_reader(const std::string& file, Read&& read) {
    try {
        check_path(read());
    } catch (const host::InputError& e) {
        if (std::string(e.what()).rfind(file + ":", 0) != 0)
            violated(std::string("message: ") + e.what());
    } catch (const std::exception& e) {
        violated(std::string("not an InputError: ") + e.what());
    }
}

inline std::string text_of(const std::uint8_t* data, std::size_t size) {
    return std::string(reinterpret_cast<const char*>(data), size);
}

}  // namespace pathstream::fuzz
