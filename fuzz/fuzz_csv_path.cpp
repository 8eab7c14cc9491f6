// The CSV path reader, every basis open and closed (the first byte picks): geometry or an
// InputError naming the file.
#include "fuzz_support.hpp"
#include "pathstream/host/csv_path.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    if (size < 1) return 0;
    const host::PathBasis bases[] = {host::PathBasis::kBSpline, host::PathBasis::kCatmullRom,
                                     host::PathBasis::kBezier, host::PathBasis::kPolyline};
    const host::PathBasis basis = bases[data[0] & 3u];
    const bool closed = (data[0] & 4u) != 0;
    const std::string text = fuzz::text_of(data + 1, size - 1);
    fuzz::check_reader("f.csv", [&] { return host::parse_csv_path(text, "f.csv", basis, closed); });
    return 0;
}
