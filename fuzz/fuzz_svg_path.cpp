// The SVG reader: geometry or an InputError naming the file.
#include "fuzz_support.hpp"
#include "pathstream/host/svg_path.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    const std::string text = fuzz::text_of(data, size);
    fuzz::check_reader("f.svg", [&] { return host::parse_svg_path(text, "f.svg"); });
    return 0;
}
