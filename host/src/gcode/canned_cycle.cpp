// Canned cycles G73, G81, G82, G83, G85, G86, G89 with G98/G99 and L repeats, as LinuxCNC
// runs them (docs/formats-gcode.md, "Canned cycles"): expanded into the rapids and feed moves
// they stand for, the drill axis being the plane's normal (Z under G17).
#include <algorithm>
#include <cmath>

#include "interpreter.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host::gcode {

namespace {
// LinuxCNC's G83 rapid-down clearance above the last peck and G73's chip-break retract
// (G83_RAPID_DELTA and G73_RETRACT: 0.010 inch).
constexpr double kPeckClearanceMm = 0.254;
constexpr double kChipBreakRetractMm = 0.254;
constexpr long kMaxRepeats = 100000;

const char* cycle_name(Motion m) {
    switch (m) {
        case Motion::kPeckChipBreak:
            return "G73";
        case Motion::kDrill:
            return "G81";
        case Motion::kDrillDwell:
            return "G82";
        case Motion::kPeck:
            return "G83";
        case Motion::kBore:
            return "G85";
        case Motion::kBoreSpindleStop:
            return "G86";
        default:
            return "G89";
    }
}
}  // namespace

void Interpreter::canned_cycle(const Command& c, Motion cycle, SourceLocation at) {
    const char* name = cycle_name(cycle);
    if (!machine()) {
        fail(at, std::string(name) +
                     ": canned cycles need a machine whose moves keep their order "
                     "(--gcode-pen machine, the default on a machine with a Z axis)");
    }
    const std::size_t drill = plane_.normal;
    const char drill_letter = kAxisLetters[drill];
    if (!on_path(drill)) {
        fail(at, std::string(name) + " drills along " + drill_letter +
                     ", which is not one of this machine's axes (" + options_.axes + ")");
    }
    if (inverse_time_) fail(at, std::string(name) + " with inverse time feed (G93): give G94");
    for (std::size_t a = 3; a < kAxisCount; ++a) {
        // LinuxCNC: no rotary word in a cycle, and U V W only where they are the plane's.
        if (const Word* w = c.value(kAxisLetters[a])) {
            fail(w->at,
                 std::string("axis word ") + w->letter + " in a canned cycle (" + name + ")");
        }
    }
    // Sticky words, as LinuxCNC: R, the bottom, Q and P stay while the same cycle repeats;
    // a new cycle mode needs them again. The initial level stays for the whole series of
    // cycle blocks (G98 returns to it; G91 R counts from it).
    const bool same = last_cycle_ == cycle;
    if (!cycle_initial_) cycle_initial_ = pos_[drill];
    const double initial = *cycle_initial_;
    const Word* r = c.value('R');
    const Word* bottom_word = c.value(drill_letter);
    if (r) {
        cycle_r_ = length(*r);
        cycle_r_incremental_ = incremental_;
    } else if (!same) {
        fail(at, std::string(name) + " needs R (the retract plane)");
    }
    if (bottom_word) {
        cycle_z_ = length(*bottom_word);
        cycle_z_incremental_ = incremental_;
    } else if (!same) {
        fail(at, std::string(name) + " needs " + drill_letter + " (the bottom of the hole)");
    }
    const double retract = cycle_r_incremental_ ? initial + cycle_r_ : cycle_r_ + offset(drill);
    const double bottom = cycle_z_incremental_ ? retract + cycle_z_ : cycle_z_ + offset(drill);
    if (bottom > retract) {
        fail(bottom_word ? bottom_word->at : at,
             std::string(name) + ": the bottom " + drill_letter + " is above the retract plane R");
    }
    if (cycle == Motion::kPeck || cycle == Motion::kPeckChipBreak) {
        if (const Word* q = c.value('Q')) {
            if (!(q->value > 0)) fail(q->at, std::string(name) + " peck depth Q must be positive");
            cycle_q_ = length(*q);
        } else if (!same) {
            fail(at, std::string(name) + " needs Q (the peck depth)");
        }
    }
    const bool dwells = cycle == Motion::kDrillDwell || cycle == Motion::kBoreSpindleStop ||
                        cycle == Motion::kBoreDwell;
    if (const Word* p = c.value('P')) {
        if (p->value < 0) fail(p->at, std::string(name) + " dwell P must not be negative");
        cycle_p_ = p->value;
    } else if (dwells && !same) {
        fail(at, std::string(name) + " needs P (the dwell at the bottom, seconds)");
    }
    long repeats = 1;
    if (const Word* l = c.value('L')) {
        if (l->value != std::floor(l->value) || l->value < 1 || l->value > kMaxRepeats) {
            fail(l->at,
                 "L (repeats) must be a whole number from 1 to " + std::to_string(kMaxRepeats));
        }
        repeats = static_cast<long>(l->value);
    }
    // The cycle's own words are not position words: targets() must not read the drill axis.
    Command position = c;
    position.values[static_cast<std::size_t>(drill_letter - 'A')].reset();
    const double clear = retract_to_r_ ? retract : std::max(initial, retract);
    last_cycle_ = cycle;
    // LinuxCNC runs a cycle in exact path mode: no corner of it is rounded.
    const CornerMode corners = runs_.corner_mode();
    const double blend = runs_.blend_tolerance();
    runs_.set_corners(CornerMode::kExactPath, 0);

    auto to = [&](double depth) {
        Axes p = pos_;
        p[drill] = depth;
        return p;
    };
    auto dwell = [&] {
        if (cycle_p_ <= 0) return;
        runs_.lift();
        runs_.dwell_next(cycle_p_, pen_down_now());
    };
    // Preliminary motion: up to R first when below it.
    if (pos_[drill] < retract) travel(to(retract), at);
    for (long k = 0; k < repeats; ++k) {
        Axes hole = targets(position, false);
        hole[drill] = pos_[drill];
        travel(hole, at);
        travel(to(retract), at);
        switch (cycle) {
            case Motion::kPeck:
            case Motion::kPeckChipBreak: {
                double depth = retract;
                while (depth > bottom) {
                    const double next = std::max(depth - cycle_q_, bottom);
                    line(to(next), at);
                    depth = next;
                    if (depth <= bottom) break;
                    if (cycle == Motion::kPeck) {
                        travel(to(retract), at);
                        travel(to(std::min(depth + kPeckClearanceMm, retract)), at);
                    } else {
                        travel(to(std::min(depth + kChipBreakRetractMm, retract)), at);
                    }
                }
                travel(to(clear), at);
                break;
            }
            case Motion::kBore:  // G85: feed out to R, then up to the clearance
                line(to(bottom), at);
                line(to(retract), at);
                if (clear > retract) travel(to(clear), at);
                break;
            case Motion::kBoreDwell:  // G89: dwell, then feed out to the clearance
                line(to(bottom), at);
                dwell();
                line(to(clear), at);
                break;
            case Motion::kBoreSpindleStop: {  // G86: the spindle stops at the bottom
                line(to(bottom), at);
                const std::uint8_t on = runs_.outputs();
                runs_.set_outputs(
                    static_cast<std::uint8_t>(on & ~(kOutputSpindle | kOutputSpindleReverse)));
                travel(to(clear), at);
                runs_.set_outputs(on);  // and starts again as it ran, after its spin-up
                break;
            }
            default:  // G81, G82
                line(to(bottom), at);
                if (dwells) dwell();
                travel(to(clear), at);
                break;
        }
    }
    runs_.set_corners(corners, blend);
    if (on_path(kZ) || drill == kZ) z_known_ = true;
}

}  // namespace pathstream::host::gcode
