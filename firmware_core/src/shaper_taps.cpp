#include "pathstream/shaper_taps.hpp"

namespace pathstream {

Status check_shaper_taps(const ShaperTap* taps, std::uint32_t count, std::uint32_t history_ticks) {
    if (count == 0) return Status::kOk;
    if (taps == nullptr || count > kMaxShaperTaps) return Status::kBadShaper;
    std::uint64_t sum = 0;
    for (std::uint32_t i = 0; i < count; ++i) {
        if (taps[i].delay >= history_ticks) return Status::kBadShaper;
        if (i > 0 && taps[i].delay <= taps[i - 1].delay) return Status::kBadShaper;
        if (taps[i].weight < 1 || taps[i].weight > kShaperWeightOne) return Status::kBadShaper;
        sum += taps[i].weight;
    }
    return sum == kShaperWeightOne ? Status::kOk : Status::kBadShaper;
}

}  // namespace pathstream
