// bench_json: is reading a JSON path linear in the file's size?
//
// Documents, generated in memory: N subpaths of three points, one subpath a text line (~46
// bytes each), N = 5,000 and 20,000. For each: parse time (best of --runs, default 3), the
// bytes the JSON index and location lookups scanned (json_bytes_scanned) and subpaths read;
// then the time ratio 20000 / 5000 (linear: ~4x).
// Target (independent of the machine's speed): at most 4 bytes scanned per byte of document;
// exit 1 when missed. Times are printed, never judged.
//
// Usage: bench_json [--quick] [--runs R] [--help]
// Exit status: 0 target met, 1 target missed or a document failed to parse, 2 usage error.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "pathstream/host/json_path.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/json_locate.hpp"

using namespace pathstream::host;

namespace {

// `n` subpaths, one per line.
std::string subpaths_document(std::size_t n) {
    std::string text = "{\"subpaths\": [\n";
    for (std::size_t i = 0; i < n; ++i) {
        const std::string x = std::to_string(i % 1000);
        text += "  {\"points\": [[" + x + ", 0], [" + x + ", 1], [" + x + ", 2]]}";
        text += i + 1 < n ? ",\n" : "\n";
    }
    return text + "]}\n";
}

struct Result {
    double ms = 1e300;
    std::size_t scanned = 0;
    std::size_t subpaths = 0;
};

Result measure(const std::string& text, int runs) {
    Result best;
    for (int r = 0; r < runs; ++r) {
        const std::size_t before = json_bytes_scanned();
        const auto t0 = std::chrono::steady_clock::now();
        const Path p = parse_json_path(text, "bench.json");
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        best.ms = std::min(best.ms, ms);
        best.scanned = json_bytes_scanned() - before;
        best.subpaths = p.subpaths.size();
    }
    return best;
}

constexpr const char* kUsageText =
    "usage: bench_json [--quick] [--runs R] [--help]\n"
    "  Parses generated JSON paths (5000 and 20000 subpaths) and prints parse times, bytes\n"
    "  scanned for locations and the time ratio.\n"
    "  --quick     one run each (the ctest smoke run)\n"
    "  --runs R    runs per document, best time kept (default 3)\n"
    "target (independent of the machine's speed): at most 4 bytes scanned per byte of document.\n"
    "exit status: 0 target met; 1 target missed or a parse failed; 2 usage error.\n";

}  // namespace

int main(int argc, char** argv) {
    int runs = 3;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--quick") {
            runs = 1;
        } else if (a == "--runs" && i + 1 < argc) {
            runs = std::atoi(argv[++i]);
        } else if (a == "--help") {
            std::fputs(kUsageText, stdout);
            return 0;
        } else {
            std::fputs(kUsageText, stderr);
            return 2;
        }
    }
    if (runs < 1) {
        std::fputs(kUsageText, stderr);
        return 2;
    }
    bool met = true;
    double ms[2] = {0, 0};
    const std::size_t sizes[2] = {5000, 20000};
    for (int k = 0; k < 2; ++k) {
        const std::string text = subpaths_document(sizes[k]);
        try {
            const Result r = measure(text, runs);
            ms[k] = r.ms;
            const double per_byte =
                static_cast<double>(r.scanned) / static_cast<double>(text.size());
            std::printf(
                "%6zu subpaths %8zu bytes: %9.2f ms, %zu subpaths read, %.2f bytes scanned per "
                "byte\n",
                sizes[k], text.size(), r.ms, r.subpaths, per_byte);
            if (per_byte > 4.0 || r.subpaths != sizes[k]) met = false;
        } catch (const InputError& e) {
            std::fprintf(stderr, "%s\n", e.what());
            return 1;
        }
    }
    std::printf("time ratio 20000 / 5000 subpaths: %.2f (linear: ~4)\n", ms[1] / ms[0]);
    std::printf("target (<= 4 bytes scanned per byte): %s\n", met ? "met" : "MISSED");
    return met ? 0 : 1;
}
