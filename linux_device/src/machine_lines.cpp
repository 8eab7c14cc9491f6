#include "pathstream/linux_device/machine_lines.hpp"

#include <stdexcept>

#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/machine/device_setup.hpp"

namespace pathstream::linux_device {

static_assert(host::kMachineFunctionCount == device::kMachineOutputCount,
              "the profile's machine functions are the device's machine outputs, in one order");

hal::GpioLineSpec line_spec(const std::string& chip, const host::GpioLineConfig& line) {
    hal::GpioLineSpec s;
    s.chip = chip;
    s.line = line.line;
    s.active_low = line.active_low;
    s.bias = line.bias == "pull-up"     ? hal::Bias::kPullUp
             : line.bias == "pull-down" ? hal::Bias::kPullDown
             : line.bias == "disable"   ? hal::Bias::kDisable
                                        : hal::Bias::kAsIs;
    return s;
}

MachineLines::~MachineLines() {
    for (auto& out : outputs_) {
        try {
            out->set(false);
        } catch (const hal::GpioError&) {
            // The line is gone (chip removed): nothing left to drive.
        }
    }
}

MachineLines MachineLines::open(const host::MachineProfile& profile) {
    const host::GpioConfig& g = profile.gpio;
    if (!g.present)
        throw std::invalid_argument(profile.source +
                                    ": the machine profile has no \"gpio\" object");
    MachineLines m;
    m.summary_ = "chip " + g.chip + ":";
    auto note = [&](const std::string& function, const host::GpioLineConfig& c) {
        m.summary_ += " " + function + "=" + c.line + (c.active_low ? " (active low)" : "");
    };
    if (g.has_enable) {
        m.outputs_.push_back(
            hal::open_gpiod_output(line_spec(g.chip, g.enable), "pathstream-enable", false));
        m.wiring_.enable = m.outputs_.back().get();
        note("enable", g.enable);
    }
    if (g.has_pen) {
        m.outputs_.push_back(
            hal::open_gpiod_output(line_spec(g.chip, g.pen), "pathstream-pen", false));
        m.wiring_.pen = m.outputs_.back().get();
        note("pen", g.pen);
    }
    for (unsigned k = 0; k < host::kMachineFunctionCount; ++k) {
        if (!g.has_function[k]) continue;
        const std::string function = host::kMachineFunctionKeys[k];
        m.outputs_.push_back(hal::open_gpiod_output(line_spec(g.chip, g.function[k]),
                                                    "pathstream-" + function, false));
        m.wiring_.machine[k] = m.outputs_.back().get();
        note(function, g.function[k]);
    }
    if (g.has_estop) {
        m.inputs_.push_back(hal::open_gpiod_input(line_spec(g.chip, g.estop), "pathstream-estop"));
        m.wiring_.estop = m.inputs_.back().get();
        note("estop", g.estop);
    }
    for (const auto& [name, line] : g.limits) {
        // The profile reader allows only "<axis name><side>" keys.
        const unsigned axis = host::axis_index(profile, name.substr(0, name.size() - 1));
        const unsigned side = name.back() == '+' ? 1u : 0u;
        m.inputs_.push_back(
            hal::open_gpiod_input(line_spec(g.chip, line), "pathstream-limit-" + name));
        m.wiring_.limit[axis][side] = m.inputs_.back().get();
        note(name, line);
    }
    return m;
}

}  // namespace pathstream::linux_device
