// Hidden points by the surfaces' exact depth: a coarse mesh, binned on the drawing, finds the
// sheets over a point; Newton's method on each finds the surface's own point there.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "pathstream/host/hidden_lines.hpp"

namespace pathstream::host {

struct Occluder::Mesh {
    struct Vertex {
        double x, y, depth, u, v;
    };
    struct Triangle {
        std::uint32_t sheet, a, b, c;  // a, b, c: indices into vertices
    };
    std::vector<SurfaceSheet> sheets;
    ViewFrame frame;
    std::vector<Vertex> vertices;
    std::vector<Triangle> triangles;
    double x0 = 0, y0 = 0, bin_w = 1, bin_h = 1;
    std::size_t bins_x = 1, bins_y = 1;
    std::vector<std::vector<std::uint32_t>> bins;
    double near_depth = 0;  // a triangle this far behind a point cannot hide it
    double same_depth = 0;  // exact depths closer than this are the same point
    double converged = 0;   // Newton's residual on the drawing that counts as a solution
    mutable std::size_t questions = 0, solves = 0;
    std::size_t max_questions = 0;

    const std::vector<std::uint32_t>* bin(double x, double y) const {
        const double i = std::floor((x - x0) / bin_w), j = std::floor((y - y0) / bin_h);
        if (i < 0 || j < 0 || i >= static_cast<double>(bins_x) ||
            j >= static_cast<double>(bins_y)) {
            return nullptr;
        }
        return &bins[static_cast<std::size_t>(j) * bins_x + static_cast<std::size_t>(i)];
    }

    // The sheet's point under drawing position (x, y), from (u, v); false when Newton fails
    // or leaves the sheet.
    bool solve(const SurfaceSheet& s, double x, double y, double& u, double& v, Point3& at) const {
        ++solves;
        const double h = 1e-6;
        for (int step = 0; step < 20; ++step) {
            at = s(u, v);
            const auto p = project_point(frame, at);
            const double gx = p[0] - x, gy = p[1] - y;
            if (std::hypot(gx, gy) <= converged)
                return u >= -1e-9 && u <= 1 + 1e-9 && v >= -1e-9 && v <= 1 + 1e-9;
            const auto pu1 = project_point(frame, s(u + h, v)),
                       pu0 = project_point(frame, s(u - h, v));
            const auto pv1 = project_point(frame, s(u, v + h)),
                       pv0 = project_point(frame, s(u, v - h));
            const double a = (pu1[0] - pu0[0]) / (2 * h), b = (pv1[0] - pv0[0]) / (2 * h);
            const double c = (pu1[1] - pu0[1]) / (2 * h), d = (pv1[1] - pv0[1]) / (2 * h);
            const double det = a * d - b * c;
            if (!(std::abs(det) > 1e-300)) return false;
            double du = -(d * gx - b * gy) / det, dv = -(-c * gx + a * gy) / det;
            const double len = std::hypot(du, dv);
            if (len > 0.25) du *= 0.25 / len, dv *= 0.25 / len;
            u += du;
            v += dv;
            if (u < -0.5 || u > 1.5 || v < -0.5 || v > 1.5) return false;
        }
        return false;
    }
};

Occluder::Occluder(std::vector<SurfaceSheet> sheets, const ViewFrame& frame, std::size_t cells,
                   std::size_t max_questions)
    : mesh_(std::make_unique<Mesh>()) {
    if (cells < 2 || cells > 256) throw std::invalid_argument("occluder cells must be 2 to 256");
    if (sheets.empty()) throw std::invalid_argument("an occluder needs at least one sheet");
    Mesh& m = *mesh_;
    m.sheets = std::move(sheets);
    m.max_questions = max_questions;
    m.frame = frame;
    const std::size_t n = cells, row = n + 1;
    double extent = 1e-300, chord = 0;
    double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
    for (std::uint32_t s = 0; s < m.sheets.size(); ++s) {
        const std::size_t base = m.vertices.size();
        for (std::size_t j = 0; j <= n; ++j) {
            for (std::size_t i = 0; i <= n; ++i) {
                const double u = static_cast<double>(i) / static_cast<double>(n);
                const double v = static_cast<double>(j) / static_cast<double>(n);
                const Point3 p = m.sheets[s](u, v);
                for (const double c : p) extent = std::max(extent, std::abs(c));
                const auto xy = project_point(frame, p);
                m.vertices.push_back({xy[0], xy[1], view_depth(frame, p), u, v});
                xmin = std::min(xmin, xy[0]), xmax = std::max(xmax, xy[0]);
                ymin = std::min(ymin, xy[1]), ymax = std::max(ymax, xy[1]);
            }
        }
        for (std::size_t j = 0; j < n; ++j) {
            for (std::size_t i = 0; i < n; ++i) {
                const auto a = static_cast<std::uint32_t>(base + j * row + i);
                const auto b = a + 1, c = static_cast<std::uint32_t>(a + row), d = c + 1;
                m.triangles.push_back({s, a, b, d});
                m.triangles.push_back({s, a, d, c});
                // How far the sheet leaves the quad's corners' mean: the mesh's depth error.
                const double u = (static_cast<double>(i) + 0.5) / static_cast<double>(n);
                const double v = (static_cast<double>(j) + 0.5) / static_cast<double>(n);
                const double mid = view_depth(frame, m.sheets[s](u, v));
                const double mean = (m.vertices[a].depth + m.vertices[b].depth +
                                     m.vertices[c].depth + m.vertices[d].depth) /
                                    4;
                chord = std::max(chord, std::abs(mid - mean));
            }
        }
    }
    m.same_depth = 1e-7 * extent;
    m.near_depth = 8 * chord + 1e-3 * extent;
    m.converged = 1e-10 * extent * frame.view.scale;
    const double pad = 1e-9 * (xmax - xmin + ymax - ymin) + 1e-12;
    m.x0 = xmin - pad;
    m.y0 = ymin - pad;
    const double side = std::sqrt(static_cast<double>(m.triangles.size()) / 4) + 1;
    m.bins_x = m.bins_y = static_cast<std::size_t>(std::clamp(side, 1.0, 512.0));
    m.bin_w = (xmax - xmin + 2 * pad) / static_cast<double>(m.bins_x);
    m.bin_h = (ymax - ymin + 2 * pad) / static_cast<double>(m.bins_y);
    m.bins.resize(m.bins_x * m.bins_y);
    for (std::uint32_t t = 0; t < m.triangles.size(); ++t) {
        const Mesh::Triangle& tr = m.triangles[t];
        const Mesh::Vertex* v[3] = {&m.vertices[tr.a], &m.vertices[tr.b], &m.vertices[tr.c]};
        const double lx = std::min({v[0]->x, v[1]->x, v[2]->x}) - pad;
        const double hx = std::max({v[0]->x, v[1]->x, v[2]->x}) + pad;
        const double ly = std::min({v[0]->y, v[1]->y, v[2]->y}) - pad;
        const double hy = std::max({v[0]->y, v[1]->y, v[2]->y}) + pad;
        const auto i0 = static_cast<std::size_t>(std::max(0.0, std::floor((lx - m.x0) / m.bin_w)));
        const auto j0 = static_cast<std::size_t>(std::max(0.0, std::floor((ly - m.y0) / m.bin_h)));
        const auto i1 =
            std::min(m.bins_x - 1, static_cast<std::size_t>(std::floor((hx - m.x0) / m.bin_w)));
        const auto j1 =
            std::min(m.bins_y - 1, static_cast<std::size_t>(std::floor((hy - m.y0) / m.bin_h)));
        for (std::size_t j = j0; j <= j1; ++j) {
            for (std::size_t i = i0; i <= i1; ++i) m.bins[j * m.bins_x + i].push_back(t);
        }
    }
}

Occluder::~Occluder() = default;

bool Occluder::hidden(const Point3& p) const {
    const Mesh& m = *mesh_;
    if (++m.questions > m.max_questions) {
        throw std::length_error("hidden-line removal needs more than " +
                                std::to_string(m.max_questions) +
                                " points judged (the reader's limit): fewer iso lines");
    }
    const auto xy = project_point(m.frame, p);
    const double depth = view_depth(m.frame, p);
    const std::vector<std::uint32_t>* list = m.bin(xy[0], xy[1]);
    if (!list) return false;
    for (const std::uint32_t t : *list) {
        const Mesh::Triangle& tr = m.triangles[t];
        const Mesh::Vertex &a = m.vertices[tr.a], &b = m.vertices[tr.b], &c = m.vertices[tr.c];
        const double det = (b.y - c.y) * (a.x - c.x) + (c.x - b.x) * (a.y - c.y);
        if (std::abs(det) < 1e-300) continue;  // edge-on: its neighbours cover the place
        const double l1 = ((b.y - c.y) * (xy[0] - c.x) + (c.x - b.x) * (xy[1] - c.y)) / det;
        const double l2 = ((c.y - a.y) * (xy[0] - c.x) + (a.x - c.x) * (xy[1] - c.y)) / det;
        const double l3 = 1 - l1 - l2;
        // A quarter of the triangle beyond its edges counts too: the mesh's outline lies inside
        // the surface's by its chord error, and Newton from there still finds the sheet.
        const double slack = -0.25;
        if (l1 < slack || l2 < slack || l3 < slack) continue;
        const double mesh_depth = l1 * a.depth + l2 * b.depth + l3 * c.depth;
        if (mesh_depth < depth - m.near_depth) continue;
        double u = l1 * a.u + l2 * b.u + l3 * c.u, v = l1 * a.v + l2 * b.v + l3 * c.v;
        Point3 at;
        if (m.solve(m.sheets[tr.sheet], xy[0], xy[1], u, v, at) &&
            view_depth(m.frame, at) > depth + m.same_depth) {
            return true;
        }
        // Near an outline the sheet folds: the point under xy on the near side and the point
        // itself on the far side are close in (u, v), and Newton may find the latter. A mesh
        // triangle well inside the point's place and nearer by more than the mesh's own depth
        // error then decides.
        const bool inside = l1 >= 0 && l2 >= 0 && l3 >= 0;
        if (inside && mesh_depth > depth + m.near_depth) return true;
    }
    return false;
}

std::size_t Occluder::questions() const {
    return mesh_->questions;
}
std::size_t Occluder::solves() const {
    return mesh_->solves;
}

}  // namespace pathstream::host
