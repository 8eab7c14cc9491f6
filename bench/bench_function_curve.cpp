// bench_function_curve: what fitting function curves costs (docs/parametric-curves.md).
//
// For each example curve (circle, ellipse, helix, Lissajous, hypotrochoid, involute flank,
// clothoid) at 0.01 mm and 0.001 mm: pieces, interval cells the proof evaluated, the largest
// proven bound and the largest error the fitter sampled, and the fit time (best of 3 runs).
// Target (independent of the machine's speed): every fit succeeds with its largest proven bound
// at most the tolerance; exit 1 when missed. Times are printed, never judged.
//
// Usage: bench_function_curve [--quick] [--markdown] [--help]
// Exit status: 0 target met, 1 a fit failed or broke its tolerance, 2 usage error.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "bench_args.hpp"
#include "curves/fit_function.hpp"

using namespace pathstream::host::curves;

namespace {

struct Example {
    const char* name;
    std::vector<const char*> coordinates;
    double t0, t1;
};

constexpr double kTwoPi = 6.283185307179586;

const char* const kUsage =
    "usage: bench_function_curve [--quick] [--markdown] [--help]\n"
    "  Fits the example function curves at 0.01 and 0.001 mm and prints pieces, proof cells,\n"
    "  bounds and times. Exit 1 when a fit fails or a bound exceeds its tolerance.\n";

}  // namespace

int main(int argc, char** argv) {
    pathstream::bench::BenchArgs args;
    if (const auto status = pathstream::bench::parse_bench_args(argc, argv, kUsage, args))
        return *status;
    const std::vector<Example> examples{
        {"circle r 40", {"40*cos(t)", "40*sin(t)"}, 0, kTwoPi},
        {"ellipse 50 x 20", {"50*cos(t)", "20*sin(t)"}, 0, kTwoPi},
        {"helix r 40, 3 turns", {"40*cos(t)", "40*sin(t)", "2*t"}, 0, 3 * kTwoPi},
        {"Lissajous 3:2", {"40*sin(3*t + pi/2)", "30*sin(2*t)"}, 0, kTwoPi},
        {"hypotrochoid",
         {"35*cos(t) + 10*cos(35/15*t)", "35*sin(t) - 10*sin(35/15*t)"},
         0,
         3 * kTwoPi},
        {"involute flank r 20", {"20*(cos(t) + t*sin(t))", "20*(sin(t) - t*cos(t))"}, 0, 0.8},
        {"clothoid a 100", {"100*fresnel_c(t)", "100*fresnel_s(t)"}, 0, 3},
    };
    const int runs = args.quick ? 1 : 3;
    const char* const row = args.markdown
                                ? "| %-20s | %7g | %6zu | %7zu | %9.3g | %9.3g | %8.2f |\n"
                                : "%-20s %7g %6zu %7zu %9.3g %9.3g %8.2f\n";
    if (args.markdown) {
        std::printf("| curve | tol mm | pieces | cells | bound mm | sampled mm | time ms |\n");
        std::printf("|---|---|---|---|---|---|---|\n");
    } else {
        std::printf("%-20s %7s %6s %7s %9s %9s %8s\n", "curve", "tol mm", "pieces", "cells",
                    "bound mm", "sampled", "time ms");
    }
    int status = 0;
    for (const double tolerance : {0.01, 0.001}) {
        for (const Example& ex : examples) {
            FunctionCurve curve;
            for (const char* text : ex.coordinates)
                curve.coordinates.push_back(parse_expression(text));
            curve.t0 = ex.t0;
            curve.t1 = ex.t1;
            double best = 1e300;
            FitFigures figures;
            try {
                for (int r = 0; r < runs; ++r) {
                    const auto start = std::chrono::steady_clock::now();
                    fit_function_curve(curve, tolerance, &figures);
                    const std::chrono::duration<double, std::milli> took =
                        std::chrono::steady_clock::now() - start;
                    best = std::min(best, took.count());
                }
            } catch (const FitError& e) {
                std::printf("%s: %s\n", ex.name, e.what());
                status = 1;
                continue;
            }
            if (figures.largest_bound > tolerance) status = 1;
            std::printf(row, ex.name, tolerance, figures.pieces, figures.cells,
                        figures.largest_bound, figures.largest_sampled_error, best);
        }
    }
    return status;
}
