#include "shaper_option.hpp"

#include <sstream>
#include <stdexcept>

#include "option_parts.hpp"

namespace pathstream::host {
namespace {

[[noreturn]] void bad(const std::string& text, const std::string& what) {
    throw std::invalid_argument("--shaper " + text + ": " + what);
}

std::vector<std::string> split(const std::string& text) {
    std::vector<std::string> parts;
    std::size_t from = 0;
    for (std::size_t colon; (colon = text.find(':', from)) != std::string::npos; from = colon + 1)
        parts.push_back(text.substr(from, colon - from));
    parts.push_back(text.substr(from));
    return parts;
}

}  // namespace

ShaperOption parse_shaper_option(const std::string& text) {
    ShaperOption o;
    if (text == "none") return o;
    const std::vector<std::string> parts = split(text);
    if (parts.size() == 2 && parts[1] == "none") {
        o.axis = parts[0];
        if (o.axis.empty()) bad(text, "the axis name is empty");
        return o;
    }
    if (parts.size() != 3 && parts.size() != 4)
        bad(text, "expected AXIS:TYPE:FREQ_HZ[:DAMPING], AXIS:none or none, e.g. x:mzv:40");
    o.axis = parts[0];
    if (o.axis.empty()) bad(text, "the axis name is empty");
    const auto type = shaper_type_from_name(parts[1]);
    if (!type)
        bad(text, "unknown shaper type \"" + parts[1] + "\" (known: " + shaper_type_names() + ")");
    ShaperSpec spec;
    spec.type = *type;
    const std::optional<double> frequency = decimal_text(parts[2]);
    if (!frequency) bad(text, "frequency \"" + parts[2] + "\" is not a number");
    if (!(*frequency > 0)) bad(text, "frequency " + parts[2] + " Hz is impossible (allowed: > 0)");
    spec.frequency_hz = *frequency;
    if (parts.size() == 4) {
        const std::optional<double> damping = decimal_text(parts[3]);
        if (!damping) bad(text, "damping \"" + parts[3] + "\" is not a number");
        if (*damping < 0 || *damping >= 1)
            bad(text, "damping " + parts[3] + " is impossible (allowed: >= 0 and < 1)");
        spec.damping = *damping;
    }
    o.spec = spec;
    return o;
}

std::vector<std::optional<ShaperSpec>> run_shapers(const std::vector<std::string>& options,
                                                   const MachineProfile& profile) {
    const std::size_t axes = profile.axes.size();
    std::vector<std::optional<ShaperSpec>> specs = profile.input_shaper;
    specs.resize(axes);
    for (const std::string& text : options) {
        const ShaperOption o = parse_shaper_option(text);
        if (o.axis.empty()) {
            specs.assign(axes, std::nullopt);
            continue;
        }
        std::size_t a = 0;
        try {
            a = profile_axis(profile, o.axis);
        } catch (const std::invalid_argument& e) {
            bad(text, e.what());
        }
        specs[a] = o.spec;
    }
    return specs;
}

std::vector<std::vector<ShaperTap>> shaper_taps(const std::vector<std::optional<ShaperSpec>>& specs,
                                                const MachineProfile& profile) {
    std::vector<std::vector<ShaperTap>> taps(specs.size());
    for (std::size_t a = 0; a < specs.size(); ++a) {
        if (!specs[a]) continue;
        try {
            taps[a] = design_shaper_taps(*specs[a], profile.tick_hz, kDeviceShaperHistoryTicks);
        } catch (const std::invalid_argument& e) {
            throw std::invalid_argument("input shaper of " + profile.axes[a].name + ": " +
                                        e.what());
        }
    }
    return taps;
}

std::string describe_shapers(const std::vector<std::optional<ShaperSpec>>& specs,
                             const std::vector<std::vector<ShaperTap>>& taps,
                             const MachineProfile& profile) {
    std::ostringstream out;
    for (std::size_t a = 0; a < specs.size() && a < taps.size(); ++a) {
        if (!specs[a]) continue;
        if (out.tellp() > 0) out << "; ";
        out << profile.axes[a].name << ": " << shaper_type_name(specs[a]->type) << " "
            << specs[a]->frequency_hz << " Hz zeta " << specs[a]->damping << ", " << taps[a].size()
            << " taps over " << shaper_duration(taps[a], profile.tick_hz) * 1000 << " ms";
    }
    return out.str();
}

}  // namespace pathstream::host
