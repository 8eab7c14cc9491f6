// The Bezier patch text reader (the teapot's form): geometry or an InputError naming the file.
// The first byte picks the view (orthographic or perspective) and hidden-line removal.
#include "fuzz_support.hpp"
#include "pathstream/host/bpt_path.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    if (size < 1) return 0;
    host::BptOptions options;
    if (data[0] & 1u) {
        options.view.projection = host::SurfaceView::Projection::kPerspective;
        options.view.eye_distance = 50;
    }
    options.hidden_lines = (data[0] & 2u) != 0;
    options.view.azimuth_deg = static_cast<double>(data[0] >> 2) * 11.0;
    // A small fraction of the reader's budgets: any input is read to its limit well within
    // the per-input timeout under the sanitizers.
    options.budget.curves = 2'000;
    options.budget.points = 100'000;
    options.budget.hidden_line_questions = 5'000;
    options.budget.fit_cells = 100'000;
    const std::string text = fuzz::text_of(data + 1, size - 1);
    fuzz::check_reader("f.bpt", [&] { return host::parse_bpt_path(text, "f.bpt", options); });
    return 0;
}
