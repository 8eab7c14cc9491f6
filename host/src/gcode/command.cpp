// G and M codes by modal group (docs/formats-gcode.md, "Codes").
#include "command.hpp"

#include <charconv>
#include <cmath>
#include <string_view>

#include "cursor.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host::gcode {

namespace {

// Modal groups, as LinuxCNC numbers them where it matters for "one per block".
enum Group {
    kNonModal,
    kMotionGroup,
    kPlane,
    kDistance,
    kArcDistance,
    kFeedMode,
    kUnits,
    kCutterComp,
    kToolLength,
    kCoordinateSystem,
    kPathControl,
    kStopping,
    kSpindle,
    kRetract,
    kToolChange,
    kCoolant,
    kSpindleSpeedMode,
    kModalState,
    kGroupCount
};

struct Seen {
    bool given = false;
    std::string name;
};

// LinuxCNC's letters: axis words, I J K offsets, D F H L P Q R S T values.
constexpr std::string_view kSupportedLetters = "ABCDFHIJKLPQRSTUVWXYZ";
constexpr const char* kSupportedLettersText = "A B C D F H I J K L P Q R S T U V W X Y Z";

class Decoder {
public:
    Decoder(const std::string& file, const std::set<std::string>& ignored)
        : file_(file), ignored_(ignored) {}

    Command decode(const Block& block) {
        Command c;
        c.start = block.start;
        const Word* unsupported = nullptr;
        bool meaningful = false;  // a code or an axis word that is not skipped
        for (const Word& w : block.words) {
            if (w.letter == 'G' || w.letter == 'M') {
                if (const auto name = code_name(w); name && ignored_.count(*name)) {
                    c.ignored.push_back({*name, w.at});
                    continue;
                }
                meaningful = true;
                if (w.letter == 'G')
                    g_word(w, c);
                else
                    m_word(w, c);
            } else if (w.letter == '@' || w.letter == '^') {
                auto& slot = w.letter == '@' ? c.polar_distance : c.polar_angle;
                if (slot) fail(w, std::string("repeated word ") + w.letter + " in one block");
                slot = w;
                meaningful = true;
            } else if (kSupportedLetters.find(w.letter) == std::string_view::npos) {
                if (!unsupported) unsupported = &w;
            } else {
                if (axis_index(w.letter) < kAxisCount) meaningful = true;
                value_word(w, c);
            }
        }
        if (!c.ignored.empty() && !meaningful) {
            c.skip = true;
            return c;
        }
        if (unsupported) {
            fail(*unsupported, std::string("unsupported word letter '") + unsupported->letter +
                                   "'" + std::string(" (supported: G M N O ") +
                                   kSupportedLettersText + ")");
        }
        return c;
    }

private:
    [[noreturn]] void fail(const Word& w, const std::string& message) const {
        throw InputError(file_, w.at, message);
    }

    void claim(Group g, const Word& w, const std::string& name) {
        if (groups_[g].given) {
            fail(w,
                 groups_[g].name + " and " + name + " are in the same modal group (one per block)");
        }
        groups_[g] = {true, name};
    }

public:
    // "M6", "G92.1" for a word that is a code LinuxCNC could know; nullopt otherwise.
    static std::optional<std::string> code_name(const Word& w) {
        if (w.letter == 'G') {
            const double tenths_exact = w.value * 10;
            const long tenths = w.value >= 0 && w.value < 1000 ? std::lround(tenths_exact) : -1;
            if (tenths < 0 || std::fabs(tenths_exact - static_cast<double>(tenths)) > 1e-6) {
                return std::nullopt;
            }
            return g_code_name(tenths);
        }
        const long code = w.value >= 0 && w.value < 100000 ? std::lround(w.value) : -1;
        if (code < 0 || std::fabs(w.value - static_cast<double>(code)) > 1e-9) return std::nullopt;
        return "M" + std::to_string(code);
    }

private:
    void g_word(const Word& w, Command& c) {
        const double tenths_exact = w.value * 10;
        const long tenths = w.value >= 0 && w.value < 1000 ? std::lround(tenths_exact) : -1;
        if (tenths < 0 || std::fabs(tenths_exact - static_cast<double>(tenths)) > 1e-6) {
            fail(w, "unsupported G code G" + w.text);
        }
        const std::string name = g_code_name(tenths);
        auto non_modal = [&](NonModal code) {
            claim(kNonModal, w, name);
            c.non_modal = code;
            c.non_modal_at = w.at;
        };
        auto motion = [&](Motion m) {
            claim(kMotionGroup, w, name);
            c.motion = m;
            c.motion_at = w.at;
        };
        switch (tenths) {
            case 0:
                motion(Motion::kRapid);
                break;
            case 10:
                motion(Motion::kLine);
                break;
            case 20:
                motion(Motion::kArcCw);
                break;
            case 30:
                motion(Motion::kArcCcw);
                break;
            case 50:
                motion(Motion::kCubic);
                break;
            case 51:
                motion(Motion::kQuadratic);
                break;
            case 52:
                motion(Motion::kNurbs);
                break;
            case 53:
                claim(kMotionGroup, w, name);
                c.nurbs_end = true;
                break;
            case 800:
                motion(Motion::kNone);
                break;
            case 40:
                non_modal(NonModal::kDwell);
                break;
            case 280:
                non_modal(NonModal::kHome);
                break;
            case 281:
                non_modal(NonModal::kSetHome);
                break;
            case 300:
                non_modal(NonModal::kHome2);
                break;
            case 301:
                non_modal(NonModal::kSetHome2);
                break;
            case 530:
                non_modal(NonModal::kMachineCoords);
                break;
            case 920:
                non_modal(NonModal::kSetOffset);
                break;
            case 921:
                non_modal(NonModal::kClearOffset);
                break;
            case 922:
                non_modal(NonModal::kSuspendOffset);
                break;
            case 923:
                non_modal(NonModal::kRestoreOffset);
                break;
            case 730:
                motion(Motion::kPeckChipBreak);
                break;
            case 810:
                motion(Motion::kDrill);
                break;
            case 820:
                motion(Motion::kDrillDwell);
                break;
            case 830:
                motion(Motion::kPeck);
                break;
            case 850:
                motion(Motion::kBore);
                break;
            case 860:
                motion(Motion::kBoreSpindleStop);
                break;
            case 890:
                motion(Motion::kBoreDwell);
                break;
            case 740:
            case 840:
            case 331:
                fail(w, name +
                            " (tapping) needs a spindle whose turning the axes follow; this "
                            "machine's spindle is an output");
            case 960:
            case 970:
                // Spindle speed mode (constant surface speed or RPM): S drives no output here,
                // so neither changes anything; D (G96's speed cap) belongs to it.
                claim(kSpindleSpeedMode, w, name);
                c.spindle_speed_mode = true;
                break;
            case 382:
            case 383:
            case 384:
            case 385:
                fail(w, name + " (probing) needs a probe input, which this machine has not");
            case 70:
            case 80:
            case 700:
            case 710:
            case 711:
            case 720:
            case 721:
                fail(w, name + " is for lathes (diameter mode, turning cycles)");
            case 330:
            case 760:
                fail(w, name + " (threading) needs a lathe spindle with an encoder");
            case 870:
            case 880:
                fail(w, name + " needs an oriented spindle stop (" +
                            (tenths == 870 ? "back boring" : "boring with a manual retract") +
                            "), which this machine has not");
            case 100:
                non_modal(NonModal::kSetCoordinates);
                break;
            case 170:
            case 180:
            case 190:
                claim(kPlane, w, name);
                c.plane = tenths == 170 ? kPlaneXY : tenths == 180 ? kPlaneZX : kPlaneYZ;
                break;
            case 200:
                claim(kUnits, w, name);
                c.inch = true;
                break;
            case 210:
                claim(kUnits, w, name);
                c.inch = false;
                break;
            case 400:
            case 410:
            case 411:
            case 420:
            case 421:
                claim(kCutterComp, w, name);
                c.cutter_comp = tenths == 400   ? CutterComp::kOff
                                : tenths == 410 ? CutterComp::kLeft
                                : tenths == 420 ? CutterComp::kRight
                                : tenths == 411 ? CutterComp::kLeftDiameter
                                                : CutterComp::kRightDiameter;
                c.cutter_comp_at = w.at;
                break;
            case 430:
            case 431:
            case 490:
                claim(kToolLength, w, name);
                c.tool_length = tenths == 430   ? ToolLength::kTable
                                : tenths == 431 ? ToolLength::kDynamic
                                                : ToolLength::kCancel;
                c.tool_length_at = w.at;
                break;
            case 540:
            case 550:
            case 560:
            case 570:
            case 580:
            case 590:
            case 591:
            case 592:
            case 593:
                claim(kCoordinateSystem, w, name);
                c.coordinate_system = tenths < 591 ? static_cast<std::size_t>((tenths - 540) / 10)
                                                   : static_cast<std::size_t>(6 + tenths - 591);
                c.coordinate_system_at = w.at;
                break;
            case 980:
            case 990:
                claim(kRetract, w, name);
                c.retract_to_r = tenths == 990;
                break;
            case 610:
            case 611:
            case 640:
                claim(kPathControl, w, name);
                c.path_control = tenths == 610   ? CornerMode::kExactPath
                                 : tenths == 611 ? CornerMode::kExactStop
                                                 : CornerMode::kBlend;
                c.path_control_at = w.at;
                break;
            case 900:
                claim(kDistance, w, name);
                c.incremental = false;
                break;
            case 910:
                claim(kDistance, w, name);
                c.incremental = true;
                break;
            case 901:
                claim(kArcDistance, w, name);
                c.arc_incremental = false;
                break;
            case 911:
                claim(kArcDistance, w, name);
                c.arc_incremental = true;
                break;
            case 930:
            case 940:
                claim(kFeedMode, w, name);
                c.inverse_time = tenths == 930;
                break;
            default:
                fail(w, "unsupported G code " + name);
        }
    }

    void m_word(const Word& w, Command& c) {
        const long code = w.value >= 0 && w.value < 100000 ? std::lround(w.value) : -1;
        if (code < 0 || std::fabs(w.value - static_cast<double>(code)) > 1e-9) {
            fail(w, "unsupported M code M" + w.text);
        }
        const std::string name = "M" + std::to_string(code);
        switch (code) {
            case 0:
            case 1:
                claim(kStopping, w, name);
                c.pause = true;
                c.pause_at = w.at;
                c.optional_stop = code == 1;
                break;
            case 60:
                claim(kStopping, w, name);
                c.pause = true;
                c.pause_at = w.at;
                c.pallet_change = true;
                break;
            case 2:
            case 30:
                claim(kStopping, w, name);
                c.end_program = true;
                break;
            case 3:
            case 4:
                claim(kSpindle, w, name);
                c.spindle_on = true;
                c.spindle_reverse = code == 4;
                c.spindle_at = w.at;
                break;
            case 5:
                claim(kSpindle, w, name);
                c.spindle_on = false;
                c.spindle_at = w.at;
                break;
            case 7:
            case 8:
                if (c.coolant_off) claim(kCoolant, w, name);  // M9 with them
                if (!groups_[kCoolant].given) groups_[kCoolant] = {true, name};
                (code == 7 ? c.mist : c.flood) = true;
                break;
            case 9:
                claim(kCoolant, w, name);
                c.coolant_off = true;
                break;
            case 70:
            case 71:
            case 72:
            case 73:
                claim(kModalState, w, name);
                c.modal_state = static_cast<int>(code);
                c.modal_state_at = w.at;
                break;
            case 61:
                claim(kToolChange, w, name);
                c.set_tool = true;
                break;
            case 6:
                claim(kToolChange, w, name);
                c.tool_change = true;
                c.pause_at = w.at;
                break;
            default:
                if (code >= 100 && code <= 199) {
                    fail(w, "user M code " + name +
                                ": LinuxCNC runs a program of that name, this reader runs none "
                                "(skip it with --ignore-code " +
                                name + " if it means nothing here)");
                }
                fail(w, "unsupported M code " + name + " (skip it with --ignore-code " + name +
                            " if it means nothing here)");
        }
    }

    void value_word(const Word& w, Command& c) {
        auto& slot = c.values[static_cast<std::size_t>(w.letter - 'A')];
        if (slot) fail(w, std::string("repeated word ") + w.letter + " in one block");
        slot = w;
    }

    const std::string& file_;
    const std::set<std::string>& ignored_;
    Seen groups_[kGroupCount];
};

}  // namespace

std::string g_code_name(long tenths) {
    std::string name = "G" + std::to_string(tenths / 10);
    if (tenths % 10 != 0) name += "." + std::to_string(tenths % 10);
    return name;
}

const std::set<std::string>& default_ignored_codes() {
    // M48-M53: LinuxCNC's override and adaptive feed switches (this machine has no overrides).
    static const std::set<std::string> codes{"M6",   "M7",   "M8",   "M9",   "M17",  "M18", "M48",
                                             "M49",  "M50",  "M51",  "M52",  "M53",  "M84", "M106",
                                             "M107", "M117", "M300", "M888", "M2000"};
    return codes;
}

std::optional<std::string> normalise_code_name(const std::string& text) {
    if (text.size() < 2) return std::nullopt;
    const char letter = upper(text[0]);
    if (letter != 'G' && letter != 'M') return std::nullopt;
    const std::string number = text.substr(1);
    double value = 0;
    const auto result = std::from_chars(number.data(), number.data() + number.size(), value);
    if (result.ec != std::errc() || result.ptr != number.data() + number.size() ||
        number.find_first_not_of("0123456789.") != std::string::npos) {
        return std::nullopt;
    }
    Word w;
    w.letter = letter;
    w.value = value;
    return Decoder::code_name(w);
}

Command decode_block(const Block& block, const std::string& file,
                     const std::set<std::string>& ignored) {
    return Decoder(file, ignored).decode(block);
}

}  // namespace pathstream::host::gcode
