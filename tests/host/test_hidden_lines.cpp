// Hidden-line removal against an independent z-buffer: the surfaces splatted point by point
// into a depth raster (no mesh, no Newton), the iso-curves sampled and judged by it, and the
// drawn path rasterised; drawn pixels the raster calls hidden and visible pixels not drawn
// must both be rare.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pathstream/host/hidden_lines.hpp"
#include "pathstream/host/json_path.hpp"
#include "pathstream/host/surface.hpp"

using namespace pathstream::host;

namespace {

struct Raster {
    double x0, y0, pixel;
    std::size_t w, h;
    std::vector<double> depth;       // the nearest surface depth per pixel
    std::vector<std::uint8_t> seen;  // reference: a visible iso-curve sample fell here
    std::vector<std::uint8_t> hid;   // reference: a hidden iso-curve sample fell here
    std::vector<std::uint8_t> drawn;

    Raster(double xmin, double ymin, double xmax, double ymax, double px)
        : x0(xmin),
          y0(ymin),
          pixel(px),
          w(static_cast<std::size_t>((xmax - xmin) / px) + 1),
          h(static_cast<std::size_t>((ymax - ymin) / px) + 1),
          depth(w * h, -INFINITY),
          seen(w * h),
          hid(w * h),
          drawn(w * h) {}

    long index(double x, double y) const {
        const double i = std::floor((x - x0) / pixel), j = std::floor((y - y0) / pixel);
        if (i < 0 || j < 0 || i >= static_cast<double>(w) || j >= static_cast<double>(h)) return -1;
        return static_cast<long>(static_cast<std::size_t>(j) * w + static_cast<std::size_t>(i));
    }
};

struct Scene {
    std::vector<BezierPatch> patches;
    ViewFrame frame;
    IsoCounts counts;
};

// The bicubic patch's point by its Bernstein weights: the test's own evaluation, apart from
// the library's de Casteljau.
Point3 surface_point(const BezierPatch& p, double u, double v) {
    const double mu = 1 - u, mv = 1 - v;
    const double bu[4] = {mu * mu * mu, 3 * mu * mu * u, 3 * mu * u * u, u * u * u};
    const double bv[4] = {mv * mv * mv, 3 * mv * mv * v, 3 * mv * v * v, v * v * v};
    Point3 s{0, 0, 0};
    for (std::size_t j = 0; j < 4; ++j) {
        for (std::size_t i = 0; i < 4; ++i) {
            const double w = bu[i] * bv[j];
            for (std::size_t k = 0; k < 3; ++k) s[k] += w * p.points[j * 4 + i][k];
        }
    }
    return s;
}

Scene teapot_scene() {
    std::ifstream in(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/teapot.json");
    std::stringstream text;
    text << in.rdbuf();
    const nlohmann::json doc = nlohmann::json::parse(text.str());
    Scene s;
    SurfaceView view;
    view.azimuth_deg = doc["view"]["azimuth"];
    view.elevation_deg = doc["view"]["elevation"];
    view.scale = doc["view"]["scale"];
    s.frame = view_frame(view);
    const auto& surface = doc["surfaces"][0];
    s.counts = {surface["iso"]["u"], surface["iso"]["v"]};
    for (const auto& indices : surface["patches"]) {
        BezierPatch p;
        for (const auto& k : indices) {
            const auto& v = surface["vertices"][k.get<std::size_t>()];
            p.points.push_back({v[0], v[1], v[2]});
        }
        s.patches.push_back(p);
    }
    return s;
}

struct Judged {
    std::size_t drawn = 0, drawn_hidden = 0, visible = 0, visible_missing = 0, not_judged = 0;
    double hidden_fraction() const {
        return static_cast<double>(drawn_hidden) / static_cast<double>(drawn);
    }
    double missing_fraction() const {
        return static_cast<double>(visible_missing) / static_cast<double>(visible);
    }
};

// The drawing of `scene` judged by a z-buffer of it.
Judged judge(const Scene& scene, const Path& drawn) {
    const double pixel = 0.25;  // mm: the drawing is about 190 mm wide
    double xmin = INFINITY, ymin = INFINITY, xmax = -INFINITY, ymax = -INFINITY;
    for (const BezierPatch& p : scene.patches) {
        for (const Point3& q : p.points) {
            const auto xy = project_point(scene.frame, q);
            xmin = std::min(xmin, xy[0]), xmax = std::max(xmax, xy[0]);
            ymin = std::min(ymin, xy[1]), ymax = std::max(ymax, xy[1]);
        }
    }
    Raster r(xmin - 1, ymin - 1, xmax + 1, ymax + 1, pixel);
    // Splat: 600 x 600 samples a patch leave no pixel of it unvisited (patches span < 80 mm).
    const int n = 600;
    for (const BezierPatch& p : scene.patches) {
        for (int j = 0; j <= n; ++j) {
            for (int i = 0; i <= n; ++i) {
                const Point3 q =
                    surface_point(p, static_cast<double>(i) / n, static_cast<double>(j) / n);
                const auto xy = project_point(scene.frame, q);
                const long k = r.index(xy[0], xy[1]);
                if (k >= 0)
                    r.depth[static_cast<std::size_t>(k)] =
                        std::max(r.depth[static_cast<std::size_t>(k)], view_depth(scene.frame, q));
            }
        }
    }
    // The reference lines: every iso-curve, judged by the raster. A sample is hidden when the
    // raster's surface is nearer the eye by more than a pixel's worth of steep slope.
    const double depth_slack = 0.02;  // model units (the teapot is 6.4 wide)
    const double edge_depth = 0.1;    // a depth range over 3 x 3 pixels that marks an edge
    for (const BezierPatch& p : scene.patches) {
        for (const bool along_u : {true, false}) {
            const std::size_t count = along_u ? scene.counts.v : scene.counts.u;
            for (std::size_t k = 0; k <= count; ++k) {
                const double fixed = static_cast<double>(k) / static_cast<double>(count);
                for (int s = 0; s <= 4000; ++s) {
                    const double t = s / 4000.0;
                    const Point3 q =
                        along_u ? surface_point(p, t, fixed) : surface_point(p, fixed, t);
                    const auto xy = project_point(scene.frame, q);
                    const long idx = r.index(xy[0], xy[1]);
                    if (idx < 0) continue;
                    const auto i = static_cast<std::size_t>(idx);
                    if (view_depth(scene.frame, q) >= r.depth[i] - depth_slack) {
                        r.seen[i] = 1;
                    } else {
                        r.hid[i] = 1;
                    }
                }
            }
        }
    }
    for (const Subpath& sp : drawn.subpaths) {
        const std::size_t pieces = (sp.points.size() - 1) / 3;
        for (std::size_t piece = 0; piece < pieces; ++piece) {
            for (int s = 0; s <= 2000; ++s) {
                const double t = s / 2000.0, m = 1 - t;
                const double w[4] = {m * m * m, 3 * m * m * t, 3 * m * t * t, t * t * t};
                double x = 0, y = 0;
                for (std::size_t i = 0; i < 4; ++i) {
                    x += w[i] * sp.points[3 * piece + i][0];
                    y += w[i] * sp.points[3 * piece + i][1];
                }
                const long idx = r.index(x, y);
                REQUIRE(idx >= 0);
                r.drawn[static_cast<std::size_t>(idx)] = 1;
            }
        }
    }
    // Within one pixel counts as the same place: lines are a pixel wide.
    auto near = [&](const std::vector<std::uint8_t>& layer, std::size_t i) {
        const long x = static_cast<long>(i % r.w), y = static_cast<long>(i / r.w);
        for (long dy = -1; dy <= 1; ++dy) {
            for (long dx = -1; dx <= 1; ++dx) {
                const long xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= static_cast<long>(r.w) ||
                    yy >= static_cast<long>(r.h))
                    continue;
                if (layer[static_cast<std::size_t>(yy) * r.w + static_cast<std::size_t>(xx)])
                    return true;
            }
        }
        return false;
    };
    // Where the raster's depth jumps or runs steep within a pixel (outlines, folds), one pixel
    // holds both near and far surface and cannot say which a line point is on: not judged.
    auto on_depth_edge = [&](std::size_t i) {
        const long x = static_cast<long>(i % r.w), y = static_cast<long>(i / r.w);
        double lo = INFINITY, hi = -INFINITY;
        for (long dy = -1; dy <= 1; ++dy) {
            for (long dx = -1; dx <= 1; ++dx) {
                const long xx = x + dx, yy = y + dy;
                if (xx < 0 || yy < 0 || xx >= static_cast<long>(r.w) ||
                    yy >= static_cast<long>(r.h))
                    return true;
                const double d =
                    r.depth[static_cast<std::size_t>(yy) * r.w + static_cast<std::size_t>(xx)];
                lo = std::min(lo, d), hi = std::max(hi, d);
            }
        }
        return !std::isfinite(lo) || hi - lo > edge_depth;
    };
    std::size_t drawn_pixels = 0, drawn_hidden = 0, visible_pixels = 0, visible_missing = 0;
    std::size_t not_judged = 0;
    for (std::size_t i = 0; i < r.w * r.h; ++i) {
        if ((r.drawn[i] || r.seen[i]) && on_depth_edge(i)) {
            ++not_judged;
            continue;
        }
        if (r.drawn[i]) {
            ++drawn_pixels;
            if (!near(r.seen, i) && near(r.hid, i)) ++drawn_hidden;
        }
        if (r.seen[i] && !r.hid[i]) {
            ++visible_pixels;
            if (!near(r.drawn, i)) ++visible_missing;
        }
    }
    if (const char* debug = std::getenv("PATHSTREAM_HIDDEN_DEBUG")) {
        std::ofstream img(debug, std::ios::binary);
        img << "P6 " << r.w << " " << r.h << " 255\n";
        for (std::size_t i = 0; i < r.w * r.h; ++i) {
            unsigned char c[3] = {255, 255, 255};
            if (std::isfinite(r.depth[i])) c[0] = c[1] = c[2] = 225;
            if (r.seen[i]) c[0] = 0, c[1] = 160, c[2] = 0;
            if (r.drawn[i]) {
                const bool bad = !near(r.seen, i) && near(r.hid, i);
                c[0] = bad ? 255 : 0, c[1] = 0, c[2] = bad ? 0 : 0;
            }
            img.write(reinterpret_cast<const char*>(c), 3);
        }
    }
    return Judged{drawn_pixels, drawn_hidden, visible_pixels, visible_missing, not_judged};
}

}  // namespace

TEST_CASE("hidden lines: the teapot against an independent z-buffer", "[surface][hidden]") {
    const Scene scene = teapot_scene();
    std::ifstream in(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/teapot.json");
    std::stringstream text;
    text << in.rdbuf();
    const Judged j = judge(scene, parse_json_path(text.str(), "teapot.json"));
    INFO("not judged (depth edges) "
         << j.not_judged << "; drawn pixels " << j.drawn << ", of them hidden by the z-buffer "
         << j.drawn_hidden << " (" << 100 * j.hidden_fraction() << " %); visible pixels "
         << j.visible << ", not drawn " << j.visible_missing << " (" << 100 * j.missing_fraction()
         << " %)");
    CHECK(j.hidden_fraction() < 0.005);
    CHECK(j.missing_fraction() < 0.005);
    CHECK(j.not_judged * 3 < j.drawn);
    // The same drawing with its hidden lines drawn fails the first figure many times over.
    std::string all = text.str();
    all.replace(all.find("\"remove\""), 8, "\"draw\"");
    const Judged k = judge(scene, parse_json_path(all, "teapot.json"));
    INFO("hidden lines drawn: " << 100 * k.hidden_fraction() << " % of drawn pixels hidden");
    CHECK(k.hidden_fraction() > 0.2);
    CHECK(k.missing_fraction() < 0.005);
}
