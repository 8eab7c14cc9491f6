// G and M codes by modal group (docs/formats-gcode.md, "Codes").
#include "command.hpp"

#include <cmath>

#include "pathstream/host/input_error.hpp"

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
    kGroupCount
};

struct Seen {
    bool given = false;
    std::string name;
};

class Decoder {
public:
    explicit Decoder(const std::string& file) : file_(file) {}

    Command decode(const Block& block) {
        Command c;
        c.start = block.start;
        for (const Word& w : block.words) {
            if (w.letter == 'G')
                g_word(w, c);
            else if (w.letter == 'M')
                m_word(w, c);
            else
                value_word(w, c);
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

    void g_word(const Word& w, Command& c) {
        const double tenths_exact = w.value * 10;
        const long tenths = w.value >= 0 && w.value < 1000 ? std::lround(tenths_exact) : -1;
        if (tenths < 0 || std::fabs(tenths_exact - static_cast<double>(tenths)) > 1e-6) {
            fail(w, "unsupported G code G" + w.text);
        }
        const std::string name = g_code_name(tenths);
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
            case 800:
                motion(Motion::kNone);
                break;
            case 40:
                claim(kNonModal, w, name);
                c.dwell = true;
                c.dwell_at = w.at;
                break;
            case 170:
                claim(kPlane, w, name);
                break;
            case 180:
            case 190:
                fail(w, "only the XY plane (G17) is supported");
            case 200:
                claim(kUnits, w, name);
                c.inch = true;
                break;
            case 210:
                claim(kUnits, w, name);
                c.inch = false;
                break;
            case 400:
                claim(kCutterComp, w, name);
                break;
            case 490:
                claim(kToolLength, w, name);
                break;
            case 540:
                claim(kCoordinateSystem, w, name);
                break;
            case 610:
            case 611:
                claim(kPathControl, w, name);
                break;
            case 640:
                claim(kPathControl, w, name);
                c.path_control = true;
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
            case 940:
                claim(kFeedMode, w, name);
                break;
            default:
                fail(w, "unsupported G code " + name);
        }
    }

    void m_word(const Word& w, Command& c) {
        const long code = w.value >= 0 && w.value < 1000 ? std::lround(w.value) : -1;
        if (code < 0 || std::fabs(w.value - static_cast<double>(code)) > 1e-9) {
            fail(w, "unsupported M code M" + w.text);
        }
        const std::string name = "M" + std::to_string(code);
        switch (code) {
            case 2:
            case 30:
                claim(kStopping, w, name);
                c.end_program = true;
                break;
            case 3:
            case 4:
                claim(kSpindle, w, name);
                c.spindle_on = true;
                break;
            case 5:
                claim(kSpindle, w, name);
                c.spindle_on = false;
                break;
            default:
                fail(w, "unsupported M code " + name);
        }
    }

    void value_word(const Word& w, Command& c) {
        auto& slot = c.values[static_cast<std::size_t>(w.letter - 'A')];
        if (slot) fail(w, std::string("repeated word ") + w.letter + " in one block");
        slot = w;
    }

    const std::string& file_;
    Seen groups_[kGroupCount];
};

}  // namespace

std::string g_code_name(long tenths) {
    std::string name = "G" + std::to_string(tenths / 10);
    if (tenths % 10 != 0) name += "." + std::to_string(tenths % 10);
    return name;
}

Command decode_block(const Block& block, const std::string& file) {
    return Decoder(file).decode(block);
}

}  // namespace pathstream::host::gcode
