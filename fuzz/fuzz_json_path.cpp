// The JSON path reader: geometry or an InputError naming the file, never anything else.
#include "fuzz_support.hpp"
#include "pathstream/host/json_path.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    const std::string text = fuzz::text_of(data, size);
    fuzz::check_reader("f.json", [&] { return host::parse_json_path(text, "f.json"); });
    return 0;
}
