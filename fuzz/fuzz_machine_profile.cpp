// The machine profile reader: a profile within its documented ranges, or an InputError naming
// the file.
#include <stdexcept>

#include "fuzz_support.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/machine/machine.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    const std::string text = fuzz::text_of(data, size);
    try {
        const host::MachineProfile p = host::parse_machine_profile(text, "m.json");
        if (p.axes.empty() || p.axes.size() > 8) fuzz::violated("axis count");
        if (!(p.tick_hz >= device::kMinTickHz && p.tick_hz <= device::kMaxTickHz))
            fuzz::violated("tick_hz");
        if (!(p.mm_per_lsb > 0)) fuzz::violated("mm_per_lsb");
    } catch (const host::InputError& e) {
        if (std::string(e.what()).rfind("m.json:", 0) != 0)
            fuzz::violated(std::string("message: ") + e.what());
    } catch (const std::exception& e) {
        fuzz::violated(std::string("not an InputError: ") + e.what());
    }
    return 0;
}
