// A limit or home switch on a simulated axis: a cam or a flag at a fixed place on the machine
// that closes while the axis is at or beyond it, opens again only once the axis is back by the
// hysteresis, and chatters for a few ticks after every change, as a mechanical contact does.
#pragma once

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/units.hpp"

namespace pathstream::sim {

/// Where a switch sits and how its contact behaves. Positions are machine positions in LSB.
struct SwitchPlacement {
    unsigned axis = 0;
    /// kNegative: active at or below `trigger`; kPositive: at or above it.
    device::LimitSide side = device::LimitSide::kNegative;
    Lsb trigger = 0;
    /// The axis must move this far back past `trigger` before the contact opens (>= 0).
    Lsb hysteresis = 0;
    /// After every change the contact opens and closes again this many times ...
    std::uint32_t bounces = 0;
    /// ... at distinct ticks among the next `bounce_ticks` (>= 2 x bounces), drawn from `seed`.
    std::uint32_t bounce_ticks = 0;
    std::uint64_t seed = 1;
};

/// One switch's contact, advanced once per tick. Host simulation only (a vector per bounce:
/// may allocate). Deterministic: the same placement and positions give the same levels.
class AxisSwitch {
public:
    /// `p.bounce_ticks` is raised to 2 x `p.bounces` when smaller; a negative hysteresis is 0.
    explicit AxisSwitch(const SwitchPlacement& p) : placement_(p), random_(p.seed) {
        placement_.hysteresis = std::max<Lsb>(0, p.hysteresis);
        placement_.bounce_ticks = std::max(p.bounce_ticks, 2 * p.bounces);
    }

    const SwitchPlacement& placement() const { return placement_; }

    /// The contact's level on the tick the axis is at `position`: closed (true) while at or
    /// beyond the trigger, open again once back past trigger -/+ hysteresis; during a bounce
    /// the level flips at the drawn ticks and ends at the settled one.
    bool update(Lsb position) {
        const bool beyond = placement_.side == device::LimitSide::kNegative
                                ? position <= placement_.trigger
                                : position >= placement_.trigger;
        const bool back = placement_.side == device::LimitSide::kNegative
                              ? position > placement_.trigger + placement_.hysteresis
                              : position < placement_.trigger - placement_.hysteresis;
        const bool was = settled_;
        if (!settled_ && beyond) settled_ = true;
        if (settled_ && back) settled_ = false;
        if (settled_ != was) {
            ++changes_;
            start_bounce();  // the change shows on this tick; its flips on later ones
        } else if (!flips_.empty()) {
            ++since_change_;
        }
        bool level = settled_;
        if (!flips_.empty()) {
            // Flips at the drawn ticks: an odd count so far shows the other level.
            const auto done = static_cast<std::size_t>(
                std::upper_bound(flips_.begin(), flips_.end(), since_change_) - flips_.begin());
            if (done % 2 == 1) level = !level;
            if (done == flips_.size()) flips_.clear();
        }
        if (level != level_) ++edges_;
        level_ = level;
        return level_;
    }

    /// The level the last update() returned.
    bool level() const { return level_; }
    /// Settled changes (closings and openings) so far.
    std::uint32_t changes() const { return changes_; }
    /// Every change of the level, bounces included.
    std::uint32_t edges() const { return edges_; }

private:
    // 2 x bounces distinct tick offsets in 1..bounce_ticks after the change, ascending.
    void start_bounce() {
        flips_.clear();
        since_change_ = 0;
        if (placement_.bounces == 0) return;
        std::vector<std::uint32_t> all(placement_.bounce_ticks);
        for (std::uint32_t i = 0; i < placement_.bounce_ticks; ++i) all[i] = i + 1;
        for (std::uint32_t i = 0; i < 2 * placement_.bounces; ++i) {
            const std::uint32_t j =
                i + static_cast<std::uint32_t>(random_() % (placement_.bounce_ticks - i));
            std::swap(all[i], all[j]);
        }
        flips_.assign(all.begin(), all.begin() + 2 * placement_.bounces);
        std::sort(flips_.begin(), flips_.end());
    }

    SwitchPlacement placement_;
    std::mt19937_64 random_;
    bool settled_ = false;
    bool level_ = false;
    std::vector<std::uint32_t> flips_;
    std::uint32_t since_change_ = 0;
    std::uint32_t changes_ = 0;
    std::uint32_t edges_ = 0;
};

}  // namespace pathstream::sim
