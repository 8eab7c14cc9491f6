#include "mode_option.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include "option_parts.hpp"

namespace pathstream::host {
namespace {

[[noreturn]] void bad(const std::string& text, const std::string& what) {
    throw std::invalid_argument("--mode " + text + ": " + what);
}

/// `part` as a whole finite decimal number, else the error names it as `what`.
double number(const std::string& text, const std::string& part, const char* what) {
    const std::optional<double> v = decimal_text(part);
    if (!v) bad(text, std::string(what) + " \"" + part + "\" is not a number");
    return *v;
}

}  // namespace

ModeOption parse_mode_option(const std::string& text) {
    const std::size_t first = text.find(':');
    const std::size_t second = first == std::string::npos ? first : text.find(':', first + 1);
    if (second == std::string::npos || text.find(':', second + 1) != std::string::npos)
        bad(text, "expected AXIS:FREQ_HZ:DAMPING, e.g. x:40:0.05");
    ModeOption o;
    o.axis = text.substr(0, first);
    if (o.axis.empty()) bad(text, "the axis name is empty");
    const std::string frequency = text.substr(first + 1, second - first - 1);
    const std::string damping = text.substr(second + 1);
    o.mode.frequency_hz = number(text, frequency, "frequency");
    if (!(o.mode.frequency_hz > 0))
        bad(text, "frequency " + frequency + " Hz is impossible (allowed: > 0)");
    o.mode.damping = number(text, damping, "damping");
    if (!(o.mode.damping > 0) || o.mode.damping > 1)
        bad(text, "damping " + damping + " is impossible (allowed: > 0 and <= 1)");
    return o;
}

std::vector<std::vector<sim::ResonantMode>> run_modes(const std::vector<std::string>& options,
                                                      const MachineProfile& profile) {
    const std::size_t axes = profile.axes.size();
    std::vector<std::vector<sim::ResonantMode>> modes(axes);
    for (std::size_t a = 0; a < axes && a < profile.resonance.size(); ++a)
        for (const ResonanceMode& m : profile.resonance[a])
            modes[a].push_back({m.frequency_hz, m.damping});
    std::vector<bool> replaced(axes, false);
    for (const std::string& text : options) {
        const ModeOption o = parse_mode_option(text);
        std::size_t a = 0;
        try {
            a = profile_axis(profile, o.axis);
        } catch (const std::invalid_argument& e) {
            bad(text, e.what());
        }
        try {
            sim::check_resonant_mode(o.mode, profile.tick_hz);
        } catch (const std::invalid_argument& e) {
            bad(text, e.what());
        }
        if (!replaced[a]) modes[a].clear();
        replaced[a] = true;
        if (modes[a].size() == kMaxResonanceModes) {
            bad(text, "axis " + o.axis + " has " + std::to_string(kMaxResonanceModes) +
                          " modes already (the most an axis may have)");
        }
        modes[a].push_back(o.mode);
    }
    bool any = false;
    for (const auto& m : modes) any = any || !m.empty();
    if (!any) modes.clear();
    return modes;
}

std::string describe_modes(const std::vector<std::vector<sim::ResonantMode>>& modes,
                           const MachineProfile& profile) {
    std::string out;
    for (std::size_t a = 0; a < modes.size() && a < profile.axes.size(); ++a) {
        if (modes[a].empty()) continue;
        out += (out.empty() ? "" : "; ") + profile.axes[a].name + ":";
        for (std::size_t i = 0; i < modes[a].size(); ++i) {
            char text[64];
            std::snprintf(text, sizeof text, "%s %.4g Hz zeta %.3g", i == 0 ? "" : ",",
                          modes[a][i].frequency_hz, modes[a][i].damping);
            out += text;
        }
    }
    return out;
}

}  // namespace pathstream::host
