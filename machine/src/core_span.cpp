#include "pathstream/machine/core_span.hpp"

#include <stdexcept>

#include "pathstream/status.hpp"

namespace pathstream::host {

Lsb core_value_at(const CoreSpan& span, std::size_t axis, std::uint32_t k) {
    Lsb v = 0;
    if (axis >= span.cubic.size() ||
        evaluate_at(span.cubic[axis], span.timing, k, v) != Status::kOk) {
        throw std::logic_error(
            "core_value_at: span not validated by uniform_core_spans, or tick beyond it");
    }
    return v;
}

}  // namespace pathstream::host
