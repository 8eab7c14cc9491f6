// The G-code reader, pen on Z or on M3/M5, or a router's X Y Z (A) machine with every move in
// order (the first byte picks): geometry or an InputError naming the file.
#include "fuzz_support.hpp"
#include "pathstream/host/gcode_path.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    if (size < 1) return 0;
    host::GcodeOptions options;
    // A hundredth of the reader's budgets: a program that spends one (a loop that never ends)
    // is read to its limit well within the fuzzer's per-input timeout, also instrumented on a
    // loaded machine. Per-line costs that grow with the input are still found.
    options.budget.blocks = 100'000;
    options.budget.characters = 5'000'000;
    options.budget.loop_passes = 10'000;
    options.budget.pieces = 20'000;
    switch (data[0] & 3u) {
        case 1:
            options.pen = host::PenControl::kSpindle;
            break;
        case 2:
            options.pen = host::PenControl::kMachine;
            options.axes = "XYZ";
            options.rapid_feed = 150;
            break;
        case 3:
            options.pen = host::PenControl::kMachine;
            options.axes = "XYZA";
            break;
        default:
            break;
    }
    const std::string text = fuzz::text_of(data + 1, size - 1);
    fuzz::check_reader("f.ngc", [&] { return host::parse_gcode_path(text, "f.ngc", options); });
    return 0;
}
