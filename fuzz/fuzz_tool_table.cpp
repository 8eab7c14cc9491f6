// The LinuxCNC tool table reader (G43 H, G41 D read it): tools with finite offsets and a
// diameter >= 0, or an InputError naming the file.
#include <cmath>

#include "../host/src/gcode/tool_table.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    const std::string text = fuzz::text_of(data, size);
    try {
        const host::gcode::ToolTable table = host::gcode::ToolTable::parse(text, "f.tbl");
        for (long t = 0; t < 64; ++t) {
            const host::gcode::ToolEntry* e = table.find(t);
            if (e == nullptr) continue;
            if (e->number != t) fuzz::violated("a tool found under another number");
            if (!(e->diameter >= 0) || !std::isfinite(e->diameter)) fuzz::violated("diameter");
            for (const double o : e->offsets) {
                if (!std::isfinite(o)) fuzz::violated("an offset that is not finite");
            }
        }
    } catch (const host::InputError& e) {
        if (std::string(e.what()).rfind("f.tbl:", 0) != 0)
            fuzz::violated(std::string("message: ") + e.what());
    } catch (const std::exception& e) {
        fuzz::violated(std::string("not an InputError: ") + e.what());
    }
    return 0;
}
