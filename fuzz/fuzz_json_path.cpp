// The JSON path reader: geometry or an InputError naming the file, never anything else.
#include "fuzz_support.hpp"
#include "pathstream/host/json_path.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream;
    const std::string text = fuzz::text_of(data, size);
    // Surfaces at a small fraction of the reader's budgets: any input is read to its limit
    // well within the per-input timeout under the sanitizers.
    host::JsonPathBudget budget;
    budget.surfaces.curves = 2'000;
    budget.surfaces.points = 100'000;
    budget.surfaces.hidden_line_questions = 5'000;
    budget.surfaces.fit_cells = 100'000;
    budget.function_cells = 100'000;
    fuzz::check_reader("f.json",
                       [&] { return host::parse_json_path(text, "f.json", 0.01, budget); });
    return 0;
}
