#include "pathstream/machine/position_argument.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pathstream::host {

bool is_lsb_argument(const std::string& text) {
    return text.size() > 3 && text.compare(text.size() - 3, 3, "lsb") == 0;
}

Lsb parse_position_argument(const std::string& text, double mm_per_lsb, const std::string& what) {
    const bool lsb = is_lsb_argument(text);
    const std::string number = lsb ? text.substr(0, text.size() - 3) : text;
    double value = 0;
    std::size_t used = 0;
    try {
        value = std::stod(number, &used);
    } catch (const std::exception&) {
        used = 0;
    }
    if (used == 0 || used != number.size() || !std::isfinite(value)) {
        throw std::invalid_argument(what + ": '" + text +
                                    "' is not a number of mm (or of LSB with the suffix lsb)");
    }
    const double in_lsb = lsb ? value : value / mm_per_lsb;
    const double whole = std::round(in_lsb);
    if (std::fabs(in_lsb - whole) > 1e-6 * std::max(1.0, std::fabs(whole))) {
        throw std::invalid_argument(what + ": '" + text + "' is not a whole number of LSB (" +
                                    std::to_string(mm_per_lsb) + " mm each)");
    }
    if (std::fabs(whole) > static_cast<double>(kMaxPositionLsb)) {
        throw std::invalid_argument(what + ": '" + text +
                                    "' is outside the core's position range (+-" +
                                    std::to_string(kMaxPositionLsb) + " LSB)");
    }
    return static_cast<Lsb>(whole);
}

}  // namespace pathstream::host
