#include "decimal_text.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>

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

}  // namespace pathstream::host
