#include "pathstream/host/isometric.hpp"

#include <cmath>

namespace pathstream::host {

std::optional<XyzAxes> xyz_axes(const MachineProfile& profile) {
    if (profile.axes.size() < 3) return std::nullopt;
    std::optional<std::size_t> found[3];
    static const char* const kNames[3] = {"x", "y", "z"};
    for (std::size_t a = 0; a < profile.axes.size(); ++a) {
        for (int k = 0; k < 3; ++k) {
            if (profile.axes[a].name == kNames[k] && !found[k]) found[k] = a;
        }
    }
    if (!found[0] || !found[1] || !found[2]) return std::nullopt;
    return XyzAxes{*found[0], *found[1], *found[2]};
}

IsometricPoint isometric(double x, double y, double z) {
    // cos 30 deg, written out so that the plots and the page (web/preview.js) agree to the bit.
    constexpr double kCos30 = 0.8660254037844386;
    return {(x + y) * kCos30, z + (y - x) * 0.5};
}

}  // namespace pathstream::host
