// Surfaces as wireframes: iso-curves of Bezier patches under orthographic views against an
// exact rational projection of the surface, seams drawn once, perspective and revolution
// surfaces within the tolerance, and the JSON form's errors.
#include <boost/multiprecision/cpp_int.hpp>
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include "pathstream/host/bpt_path.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/surface.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;
using Q = boost::multiprecision::cpp_rational;

namespace {

constexpr double kLsbMm = 0.001;

// Bernstein weight C(n, i) t^i (1 - t)^(n - i), exactly.
Q bernstein(int n, int i, const Q& t) {
    static const int binomial[4][4] = {{1, 0, 0, 0}, {1, 1, 0, 0}, {1, 2, 1, 0}, {1, 3, 3, 1}};
    Q w = binomial[n][i];
    for (int k = 0; k < i; ++k) w *= t;
    for (int k = 0; k < n - i; ++k) w *= (1 - t);
    return w;
}

// The drawing's point of S(u, v) through `frame`, exactly (the frame's doubles as given).
std::array<Q, 2> exact_projection(const BezierPatch& p, const ViewFrame& f, const Q& u,
                                  const Q& v) {
    std::array<Q, 3> s{0, 0, 0};
    for (int j = 0; j <= p.degree_v; ++j) {
        for (int i = 0; i <= p.degree_u; ++i) {
            const Q w = bernstein(p.degree_u, i, u) * bernstein(p.degree_v, j, v);
            const Point3& c = p.points[static_cast<std::size_t>(j * (p.degree_u + 1) + i)];
            for (int k = 0; k < 3; ++k) s[k] += w * Q(c[k]);
        }
    }
    Q x = 0, y = 0;
    for (int k = 0; k < 3; ++k) {
        x += Q(f.right[k]) * s[k];
        y -= Q(f.up[k]) * s[k];
    }
    return {Q(f.view.scale) * x, Q(f.view.scale) * y};
}

// The drawn cubic at parameter t, exactly from its double control points.
std::array<Q, 2> exact_bezier(const Subpath& sp, std::size_t piece, const Q& t) {
    std::array<Q, 2> out{0, 0};
    for (int i = 0; i < 4; ++i) {
        const Q w = bernstein(3, i, t);
        for (int k = 0; k < 2; ++k)
            out[k] += w * Q(sp.points[3 * piece + static_cast<std::size_t>(i)][k]);
    }
    return out;
}

double distance(const std::array<Q, 2>& a, const std::array<Q, 2>& b) {
    const double dx = static_cast<double>(a[0] - b[0]), dy = static_cast<double>(a[1] - b[1]);
    return std::hypot(dx, dy);
}

BezierPatch random_patch(std::mt19937_64& rng, int du, int dv) {
    std::uniform_real_distribution<double> coordinate(-200.0, 200.0);
    BezierPatch p;
    p.degree_u = du;
    p.degree_v = dv;
    for (int k = 0; k < (du + 1) * (dv + 1); ++k) {
        p.points.push_back({coordinate(rng), coordinate(rng), coordinate(rng)});
    }
    return p;
}

SurfaceView random_view(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> angle(-180.0, 180.0), scale(0.1, 3.0);
    SurfaceView v;
    v.azimuth_deg = angle(rng);
    v.elevation_deg = angle(rng) / 2;
    v.roll_deg = angle(rng);
    v.scale = scale(rng);
    return v;
}

// The smallest of f over [lo, hi] near the best of `samples` + 1 even samples, refined by a
// ternary search around it (the distance functions here are unimodal that close).
template <class F>
double minimum(const F& f, double lo, double hi, int samples) {
    int best = 0;
    double best_value = INFINITY;
    for (int k = 0; k <= samples; ++k) {
        const double v = f(lo + (hi - lo) * k / samples);
        if (v < best_value) best_value = v, best = k;
    }
    const double h = (hi - lo) / samples;
    double a = std::max(lo, lo + h * (best - 1)), b = std::min(hi, lo + h * (best + 1));
    for (int i = 0; i < 60; ++i) {
        const double m1 = a + (b - a) / 3, m2 = b - (b - a) / 3;
        if (f(m1) < f(m2)) {
            b = m2;
        } else {
            a = m1;
        }
    }
    return std::min(best_value, f((a + b) / 2));
}

std::array<double, 2> chain_point(const Subpath& curve, std::size_t piece, double t) {
    const double s = 1 - t;
    const double w[4] = {s * s * s, 3 * s * s * t, 3 * s * t * t, t * t * t};
    std::array<double, 2> out{0, 0};
    for (int i = 0; i < 4; ++i) {
        for (std::size_t k = 0; k < 2; ++k) {
            out[k] += w[i] * curve.points[3 * piece + static_cast<std::size_t>(i)][k];
        }
    }
    return out;
}

// Distance from `p` to the drawn chain `curve`.
double distance_to_chain(const std::array<double, 2>& p, const Subpath& curve) {
    double best = INFINITY;
    const std::size_t pieces = (curve.points.size() - 1) / 3;
    for (std::size_t piece = 0; piece < pieces; ++piece) {
        best = std::min(best, minimum(
                                  [&](double t) {
                                      const auto q = chain_point(curve, piece, t);
                                      return std::hypot(q[0] - p[0], q[1] - p[1]);
                                  },
                                  0.0, 1.0, 64));
    }
    return best;
}

}  // namespace

TEST_CASE("surface: iso-curves of random patches equal the exact projection", "[surface]") {
    std::mt19937_64 rng(Catch::rngSeed());
    const int cases = 60;
    double worst = 0;
    std::size_t checked = 0;
    for (int c = 0; c < cases; ++c) {
        const int du = 1 + c % 3, dv = 1 + (c / 3) % 3;
        const BezierPatch patch = random_patch(rng, du, dv);
        const ViewFrame frame = view_frame(random_view(rng));
        const IsoCounts counts{3 + static_cast<std::size_t>(c % 4),
                               2 + static_cast<std::size_t>(c % 5)};
        WireframeFigures figures;
        const std::vector<Subpath> curves = patch_wireframe({patch}, counts, frame, 0.01, &figures);
        REQUIRE(curves.size() == counts.u + counts.v + 2);
        CHECK(figures.exact_curves == curves.size());
        CHECK(figures.seams_merged == 0);
        std::size_t index = 0;
        for (const bool along_u : {true, false}) {
            const std::size_t n = along_u ? counts.v : counts.u;
            for (std::size_t k = 0; k <= n; ++k, ++index) {
                const Subpath& sp = curves[index];
                REQUIRE(sp.points.size() == 4);
                const Q fixed(static_cast<long>(k), static_cast<long>(n));
                for (int s = 0; s <= 16; ++s) {
                    const Q t(s, 16);
                    const auto want = along_u ? exact_projection(patch, frame, t, fixed)
                                              : exact_projection(patch, frame, fixed, t);
                    worst = std::max(worst, distance(exact_bezier(sp, 0, t), want));
                    ++checked;
                }
            }
        }
    }
    INFO("worst distance " << worst << " mm over " << checked << " samples");
    CHECK(worst <= 0.5 * kLsbMm);
    CHECK(checked > 3000);
}

TEST_CASE("surface: the teapot's shared seams are drawn once", "[surface]") {
    const Path teapot =
        load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/teapot.json");
    CHECK(teapot.axes == 2);
    // Two curves that are the same (in either direction) would be drawn twice.
    for (std::size_t a = 0; a < teapot.subpaths.size(); ++a) {
        for (std::size_t b = a + 1; b < teapot.subpaths.size(); ++b) {
            const PointList& p = teapot.subpaths[a].points;
            const PointList& q = teapot.subpaths[b].points;
            if (p.size() != q.size()) continue;
            bool same = true, reversed = true;
            for (std::size_t i = 0; i < p.size(); ++i) {
                for (std::size_t k = 0; k < 2; ++k) {
                    same = same && std::abs(p[i][k] - q[i][k]) < 1e-6;
                    reversed = reversed && std::abs(p[i][k] - q[p.size() - 1 - i][k]) < 1e-6;
                }
            }
            INFO("subpaths " << a << " and " << b);
            CHECK(!(same || reversed));
        }
    }
}

TEST_CASE("surface: seams and degenerate edges are counted", "[surface]") {
    std::vector<BezierPatch> two(2);
    for (int k = 0; k < 2; ++k) {
        two[static_cast<std::size_t>(k)].degree_u = two[static_cast<std::size_t>(k)].degree_v = 1;
        const double x0 = k;
        // The second patch's u = 0 edge is the first's u = 1 edge.
        two[static_cast<std::size_t>(k)].points = {
            {x0, 0, 0}, {x0 + 1, 0, 0}, {x0, 1, 0}, {x0 + 1, 1, 0}};
    }
    WireframeFigures f;
    const auto curves = patch_wireframe(two, {1, 1}, view_frame(SurfaceView{}), 0.01, &f);
    CHECK(f.seams_merged == 1);
    CHECK(curves.size() == 7);
    BezierPatch cone;  // all of the v = 1 row in one point: an apex
    cone.degree_u = cone.degree_v = 1;
    cone.points = {{0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 0, 1}};
    patch_wireframe({cone}, {2, 2}, view_frame(SurfaceView{}), 0.01, &f);
    CHECK(f.degenerate == 1);
}

TEST_CASE("surface: perspective iso-curves are fitted within the tolerance", "[surface]") {
    std::mt19937_64 rng(Catch::rngSeed() + 1);
    const double tolerance = 0.01;
    double worst = 0;
    for (int c = 0; c < 8; ++c) {
        const BezierPatch patch = random_patch(rng, 3, 3);
        SurfaceView view = random_view(rng);
        view.projection = SurfaceView::Projection::kPerspective;
        view.eye_distance = 900;  // the patch is within 200 * sqrt(3) of the origin
        const ViewFrame frame = view_frame(view);
        WireframeFigures f;
        const auto curves = patch_wireframe({patch}, {2, 2}, frame, tolerance, &f);
        REQUIRE(curves.size() == 6);
        CHECK(f.exact_curves == 0);
        std::size_t index = 0;
        for (const bool along_u : {true, false}) {
            for (int k = 0; k <= 2; ++k, ++index) {
                for (int s = 0; s <= 120; ++s) {
                    const double t = s / 120.0, fixed = k / 2.0;
                    const Point3 p =
                        along_u ? patch_point(patch, t, fixed) : patch_point(patch, fixed, t);
                    worst =
                        std::max(worst, distance_to_chain(project_point(frame, p), curves[index]));
                }
            }
        }
    }
    INFO("worst distance to the drawn curve " << worst << " mm");
    CHECK(worst <= tolerance);
}

TEST_CASE("surface: a surface of revolution's meridians and parallels", "[surface]") {
    RevolutionSurface vase;
    Path profile;
    profile.axes = 2;
    Subpath sp;
    sp.basis = PathBasis::kBezier;
    sp.points.push_back({20, 0});
    sp.points.push_back({40, 20});
    sp.points.push_back({10, 50});
    sp.points.push_back({15, 80});
    profile.subpaths.push_back(sp);
    vase.profile = to_bezier_segments(profile);
    vase.axis_point = {5, -3, 2};
    vase.axis_direction = {0.2, 0.1, 1};
    SurfaceView view;
    view.azimuth_deg = 20;
    view.elevation_deg = 35;
    view.scale = 2;
    const ViewFrame frame = view_frame(view);
    const double tolerance = 0.005;
    WireframeFigures f;
    const auto curves = revolution_wireframe(vase, {8, 3}, frame, tolerance, &f);
    CHECK(f.seams_merged == 1);     // the 360 degree meridian is the 0 degree one
    CHECK(curves.size() == 8 + 4);  // 8 meridians, 4 parallels
    CHECK(f.exact_curves == 8);
    // Every drawn point lies on the surface's projection: each parallel on its circle.
    const double n = std::sqrt(1.05);
    const Point3 a = {0.2 / n, 0.1 / n, 1 / n};
    const double l1 = std::hypot(a[2], a[0]);
    const Point3 e1 = {a[2] / l1, 0, -a[0] / l1};  // two directions across the axis
    const Point3 e2 = {a[1] * e1[2] - a[2] * e1[1], a[2] * e1[0] - a[0] * e1[2],
                       a[0] * e1[1] - a[1] * e1[0]};
    for (std::size_t c = 8; c < curves.size(); ++c) {
        const PathPoint rh = bezier_point(vase.profile[0], static_cast<double>(c - 8) / 3);
        auto circle = [&](double th) {
            Point3 p;
            for (std::size_t i = 0; i < 3; ++i) {
                p[i] = vase.axis_point[i] + rh[1] * a[i] +
                       rh[0] * (std::cos(th) * e1[i] + std::sin(th) * e2[i]);
            }
            return project_point(frame, p);
        };
        double worst = 0;
        const std::size_t pieces = (curves[c].points.size() - 1) / 3;
        for (std::size_t piece = 0; piece < pieces; ++piece) {
            for (int k = 0; k <= 50; ++k) {
                const auto x = chain_point(curves[c], piece, k / 50.0);
                worst = std::max(worst, minimum(
                                            [&](double th) {
                                                const auto q = circle(th);
                                                return std::hypot(x[0] - q[0], x[1] - q[1]);
                                            },
                                            0.0, 2 * M_PI, 720));
            }
        }
        INFO("parallel " << c - 8 << ": worst " << worst << " mm");
        CHECK(worst <= tolerance);
        CHECK(worst > 0);  // a fit, not the circle itself
    }
}

TEST_CASE("surface: the JSON form's errors name the place", "[surface]") {
    auto error_of = [](const std::string& text) {
        try {
            parse_json_path(text, "s.json");
        } catch (const pathstream::host::InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of(R"({"surfaces": [{"type": "bezier", "degree": 1, "patches": [[[0,0,0]]]}]})") ==
          "s.json:1:59: a patch of degree 1 x 1 has 4 control points");
    CHECK(error_of(R"({"surfaces": [{"type": "cone"}]})") ==
          "s.json:1:24: type must be \"bezier\" or \"revolution\"");
    CHECK(error_of(R"({"surfaces": [{"type": "bezier", "degree": 4, "patches": []}]})") ==
          "s.json:1:44: degree must be a whole number from 1 to 3");
    CHECK(error_of(R"({"view": {"projection": "fisheye"}, "surfaces": []})") ==
          "s.json:1:25: projection must be \"orthographic\" or \"perspective\"");
    CHECK(error_of(R"({"view": {"projection": "perspective"}, "points": [[0,0,0],[1,1,1]]})") ==
          "s.json:1:10: a perspective view needs \"eye_distance\" (model units from the origin)");
    CHECK(
        error_of(
            R"({"view": {"projection": "perspective", "eye_distance": 1}, "points": [[0,0,0],[0,0,5]], "basis": "polyline"})")
            .find("not in front of the eye") != std::string::npos);
    CHECK(
        error_of(
            R"({"surfaces": [{"type": "bezier", "degree": 1, "vertices": [[0,0,0]], "patches": [[0,0,0,1]]}]})") ==
        "s.json:1:89: a vertex index must be a whole number from 0 to 0");
    CHECK(error_of(R"({"surfaces": [{"type": "revolution", "profile": {"points": [[1, 0]]}}]})") ==
          "s.json:1:60: open bspline needs at least 2 points, got 1");
    CHECK(error_of(R"({"surfaces": [{"type": "bezier", "iso": {"u": 100000}, "patches": []}]})") ==
          "s.json:1:47: iso u must be a whole number from 0 to 1000");
}

TEST_CASE("surface: a 3-D path under a view is projected exactly", "[surface]") {
    const Path p = parse_json_path(
        R"({"view": {"azimuth": 0, "elevation": 0, "scale": 2}, "basis": "polyline", "points": [[0, 0, 0], [0, 10, 5]]})",
        "v.json");
    REQUIRE(p.axes == 2);
    REQUIRE(p.subpaths.size() == 1);
    // Looking along -x: y runs right, z up (drawn as -y).
    CHECK(p.subpaths[0].points.back()[0] == Approx(20));
    CHECK(p.subpaths[0].points.back()[1] == Approx(-10));
}

TEST_CASE("surface: the teapot's text form draws as its JSON form", "[surface]") {
    std::ifstream in(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/teapot.bpt");
    std::stringstream text;
    text << in.rdbuf();
    BptOptions options;
    options.view.azimuth_deg = -70;  // the view examples/teapot.json gives
    options.view.elevation_deg = 25;
    options.view.scale = 30;
    const Path bpt = parse_bpt_path(text.str(), "teapot.bpt", options);
    const Path json = load_json_path(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/teapot.json");
    REQUIRE(bpt.subpaths.size() == json.subpaths.size());
    for (std::size_t i = 0; i < bpt.subpaths.size(); ++i) {
        REQUIRE(bpt.subpaths[i].points.size() == json.subpaths[i].points.size());
        for (std::size_t k = 0; k < bpt.subpaths[i].points.size(); ++k) {
            CHECK(bpt.subpaths[i].points[k] == json.subpaths[i].points[k]);
        }
    }
}

TEST_CASE("surface: the text form's errors name the place", "[surface]") {
    auto error_of = [](const std::string& text) {
        try {
            parse_bpt_path(text, "t.bpt");
        } catch (const pathstream::host::InputError& e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error_of("") == "t.bpt:1:1: missing the patch count");
    CHECK(error_of("0\n") == "t.bpt:1:1: the patch count must be a whole number from 1 to 100000");
    CHECK(error_of("1\n3 4\n") ==
          "t.bpt:2:3: a patch's v degree must be a whole number from 1 to 3");
    CHECK(error_of("1\n1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 x\n") ==
          "t.bpt:6:5: a coordinate must be a finite number, got \"x\"");
    CHECK(error_of("1\n1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 1e7\n") ==
          "t.bpt:6:5: coordinate is out of range (|value| <= 1e6 mm)");
    CHECK(error_of("1\n1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n5\n") ==
          "t.bpt:7:1: data after the 1 patches the file announces");
    CHECK(error_of("2\n1 1\n0 0 0\n1 0 0\n0 1 0\n1 1 1\n") ==
          "t.bpt:7:1: missing a patch's u degree");
    CHECK(error_of("1\n1 1\n0 0 0\n0 0 0\n0 0 0\n0 0 0\n") == "t.bpt: the patches draw no curve");
}
