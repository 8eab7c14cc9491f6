// What `pathstream eval` prints (the core's Horner value of each span at u = j/N) against an
// independent double-precision evaluation of the same bases from the file's points: they
// agree to half an LSB, the core's rounding, on every sample.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <sstream>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/json_path.hpp"

using namespace pathstream::host;

namespace {

/// Closed-form basis weights at u (textbook forms, not the core's matrices).
void weights(PathBasis basis, double u, double w[4]) {
    const double v = 1 - u;
    switch (basis) {
        case PathBasis::kBSpline:
            w[0] = v * v * v / 6;
            w[1] = (3 * u * u * u - 6 * u * u + 4) / 6;
            w[2] = (-3 * u * u * u + 3 * u * u + 3 * u + 1) / 6;
            w[3] = u * u * u / 6;
            break;
        case PathBasis::kCatmullRom:
            w[0] = (-u * v * v) / 2;
            w[1] = (3 * u * u * u - 5 * u * u + 2) / 2;
            w[2] = (-3 * u * u * u + 4 * u * u + u) / 2;
            w[3] = (-u * u * v) / 2;
            break;
        case PathBasis::kBezier:
            w[0] = v * v * v;
            w[1] = 3 * u * v * v;
            w[2] = 3 * u * u * v;
            w[3] = u * u * u;
            break;
        case PathBasis::kPolyline:
            w[0] = v;
            w[1] = u;
            w[2] = w[3] = 0;
            break;
    }
}

/// The four points (mm, already quantised to LSB as the file's points are) of span i of an
/// open subpath, with the clamped ends 2 P0 - P1 for B-spline and Catmull-Rom.
std::vector<double> window(const Subpath& sp, std::size_t i, std::size_t axis, double lsb) {
    std::vector<double> q;
    for (const auto& p : sp.points) q.push_back(std::round(p[axis] / lsb) * lsb);
    const std::size_t m = q.size();
    switch (sp.basis) {
        case PathBasis::kBSpline:
        case PathBasis::kCatmullRom: {
            std::vector<double> ext{2 * q[0] - q[1]};
            ext.insert(ext.end(), q.begin(), q.end());
            ext.push_back(2 * q[m - 1] - q[m - 2]);
            return {ext[i], ext[i + 1], ext[i + 2], ext[i + 3]};
        }
        case PathBasis::kBezier:
            return {q[3 * i], q[3 * i + 1], q[3 * i + 2], q[3 * i + 3]};
        case PathBasis::kPolyline:
            return {q[i], q[i + 1], 0, 0};
    }
    return {};
}

}  // namespace

TEST_CASE("eval's core values equal an independent double evaluation to half an LSB",
          "[host][eval]") {
    std::mt19937_64 rng(20261122);
    std::uniform_real_distribution<double> coord(-300.0, 300.0);
    const double lsb = 0.001;
    const std::uint32_t n = 16;
    for (const char* basis : {"bspline", "catmull-rom", "bezier", "polyline"}) {
        for (int trial = 0; trial < 20; ++trial) {
            const std::size_t points =
                std::string(basis) == "bezier" ? 3 * (1 + rng() % 5) + 1 : 2 + rng() % 8;
            std::ostringstream doc;
            doc.precision(17);
            doc << "{\"basis\": \"" << basis << "\", \"points\": [";
            for (std::size_t i = 0; i < points; ++i)
                doc << (i ? "," : "") << "[" << coord(rng) << "," << coord(rng) << "]";
            doc << "]}";
            const Path path = parse_json_path(doc.str(), "t.json");
            const auto spans = uniform_core_spans(path, "t.json", lsb, n);
            const Subpath& sp = path.subpaths[0];
            for (std::size_t i = 0; i < spans.size(); ++i) {
                for (std::size_t a = 0; a < 2; ++a) {
                    const auto p = window(sp, i, a, lsb);
                    for (std::uint32_t k = 0; k <= n; ++k) {
                        double w[4] = {0, 0, 0, 0};
                        weights(sp.basis, static_cast<double>(k) / n, w);
                        const double expected =
                            w[0] * p[0] + w[1] * p[1] + w[2] * p[2] + w[3] * p[3];
                        const double got = core_value_at(spans[i], a, k) * lsb;
                        INFO(basis << " span " << i << " axis " << a << " k " << k);
                        REQUIRE(std::fabs(got - expected) <= lsb / 2 + 1e-9);
                    }
                }
            }
        }
    }
}
