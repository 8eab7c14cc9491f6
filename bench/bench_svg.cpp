// bench_svg: is reading an SVG linear in the file's size?
//
// Documents, generated in memory (one user unit = 1 mm):
//   * lines N    : N <line> elements, one per text line, N = 2,000, 4,000 and 8,000;
//   * padded     : the 2,000 lines with whitespace and comments between them, 2 MB in all;
//   * circles    : ~10,000 <circle>s in groups with transforms and style attributes, ~2.5 MB
//                  (a stipple drawing as Inkscape and StippleGen write it).
// For each: parse time (best of --runs, default 3), the bytes the location lookup scanned
// (SvgReadInfo::location_bytes_scanned) and subpaths read; then the time ratios lines 8000 /
// lines 2000 and padded / lines 2000 (linear: 4x and ~1x plus the extra bytes' scan).
// Target (independent of the machine's speed): the location lookup scans at most 2 bytes per
// byte of document in every case; exit 1 when missed. Times are printed, never judged.
//
// Usage: bench_svg [--quick] [--runs R] [--help]
// Exit status: 0 target met, 1 target missed or a document failed to parse, 2 usage error.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

const std::string kHead =
    "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"400mm\" height=\"400mm\" "
    "viewBox=\"0 0 400 400\">\n";

// `n` lines, each followed by `pad` bytes of whitespace and comments.
std::string lines_document(std::size_t n, std::size_t pad) {
    std::string s = kHead;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0, 400);
    char buf[160];
    for (std::size_t i = 0; i < n; ++i) {
        std::snprintf(
            buf, sizeof buf,
            "  <line x1=\"%.3f\" y1=\"%.3f\" x2=\"%.3f\" y2=\"%.3f\" stroke=\"black\"/>\n", u(rng),
            u(rng), u(rng), u(rng));
        s += buf;
        std::size_t left = pad;
        while (left > 0) {
            const std::string chunk =
                "  <!-- padding padding padding padding padding -->\n"
                "                                                  \n";
            const std::size_t take = std::min(left, chunk.size());
            s.append(chunk, 0, take);
            left -= take;
        }
    }
    return s + "</svg>\n";
}

// ~`n` circles in groups of 100, each group translated, ~250 bytes a circle.
std::string circles_document(std::size_t n) {
    std::string s = kHead;
    s += "<style>.dot{stroke:#000000}</style>\n";
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0, 40), r(0.2, 0.9);
    char buf[320];
    for (std::size_t i = 0; i < n; ++i) {
        if (i % 100 == 0) {
            if (i > 0) s += "  </g>\n";
            std::snprintf(buf, sizeof buf, "  <g transform=\"translate(%zu,%zu)\" id=\"g%zu\">\n",
                          (i / 100) % 10 * 40, (i / 1000) * 40, i / 100);
            s += buf;
        }
        std::snprintf(buf, sizeof buf,
                      "    <circle class=\"dot\" id=\"c%zu\" cx=\"%.6f\" cy=\"%.6f\" r=\"%.6f\" "
                      "style=\"fill:none;stroke:#000000;stroke-width:0.1;stroke-opacity:1;"
                      "stroke-linecap:round;stroke-linejoin:round;stroke-miterlimit:4;"
                      "stroke-dasharray:none;fill-opacity:1;paint-order:normal\"/>\n",
                      i, u(rng), u(rng), r(rng));
        s += buf;
    }
    return s + "  </g>\n</svg>\n";
}

struct Result {
    double ms = 0;
    std::size_t scanned = 0;
    std::size_t subpaths = 0;
};

Result measure(const std::string& text, int runs) {
    Result best;
    best.ms = 1e300;
    for (int r = 0; r < runs; ++r) {
        svg::SvgReadInfo info;
        const auto t0 = std::chrono::steady_clock::now();
        const Path p = parse_svg_path(text, "bench.svg", 0.01, &info);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count();
        best.ms = std::min(best.ms, ms);
        best.scanned = info.location_bytes_scanned;
        best.subpaths = p.subpaths.size();
    }
    return best;
}

constexpr const char* kUsageText =
    "usage: bench_svg [--quick] [--runs R] [--help]\n"
    "  Parses generated SVG documents (2000/4000/8000 lines, 2000 lines padded to 2 MB, ~10000\n"
    "  circles in ~2.5 MB) and prints parse times and ratios.\n"
    "  --quick     one run each, 1000 circles (the ctest smoke run)\n"
    "  --runs R    runs per document, best time kept (default 3)\n"
    "target (independent of the machine's speed): the location lookup scans at most 2 bytes per\n"
    "byte of document. Times are printed, never judged.\n"
    "exit status: 0 target met; 1 target missed or a parse failed; 2 usage error.\n";

}  // namespace

int main(int argc, char** argv) {
    int runs = 3;
    bool quick = false;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (a == "--quick") {
            quick = true;
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
    if (quick) runs = 1;
    struct Case {
        std::string name;
        std::string text;
    };
    std::vector<Case> cases;
    for (std::size_t n : {2000, 4000, 8000})
        cases.push_back({"lines " + std::to_string(n), lines_document(n, 0)});
    cases.push_back({"lines 2000 padded", lines_document(2000, 2000000 / 2000)});
    cases.push_back({"circles", circles_document(quick ? 1000 : 9841)});

    bool met = true;
    std::vector<Result> results;
    std::printf("%-20s %10s %10s %12s %14s\n", "document", "bytes", "subpaths", "parse ms",
                "located bytes");
    for (const Case& c : cases) {
        Result r;
        try {
            r = measure(c.text, runs);
        } catch (const InputError& e) {
            std::printf("%s: %s\n", c.name.c_str(), e.what());
            return 1;
        }
        results.push_back(r);
        const bool ok = r.scanned <= 2 * c.text.size();
        met = met && ok;
        std::printf("%-20s %10zu %10zu %12.1f %14zu%s\n", c.name.c_str(), c.text.size(), r.subpaths,
                    r.ms, r.scanned, ok ? "" : "  (over 2 bytes per byte: MISSED)");
    }
    std::printf("time ratio lines 8000 / 2000: %.2fx (linear: 4x)\n",
                results[2].ms / results[0].ms);
    std::printf("time ratio lines 4000 / 2000: %.2fx (linear: 2x)\n",
                results[1].ms / results[0].ms);
    std::printf(
        "time ratio padded 2 MB / lines 2000: %.2fx (same elements, %.0fx the bytes)\n",
        results[3].ms / results[0].ms,
        static_cast<double>(cases[3].text.size()) / static_cast<double>(cases[0].text.size()));
    return met ? 0 : 1;
}
