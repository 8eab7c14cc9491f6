#include "option_parts.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace pathstream::host {

std::optional<double> decimal_text(const std::string& part) {
    const char* begin = part.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(begin, &end);
    if (part.empty() || end != begin + part.size() || errno == ERANGE || !std::isfinite(v))
        return std::nullopt;
    return v;
}

std::size_t profile_axis(const MachineProfile& profile, const std::string& name) {
    for (std::size_t a = 0; a < profile.axes.size(); ++a)
        if (profile.axes[a].name == name) return a;
    std::string names;
    for (const AxisLimits& x : profile.axes) names += (names.empty() ? "" : ", ") + x.name;
    throw std::invalid_argument("axis \"" + name +
                                "\" is not in the machine profile (axes: " + names + ")");
}

}  // namespace pathstream::host
