// Arc -> cubic Beziers with the tangent-length rule h = 4/3 tan(θ/4), whose largest radial
// error on a circle of radius r is r · 2/27 · sin⁶(θ/4) / cos²(θ/4) (outward, mid-piece).
#include "arc.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace pathstream::host::gcode {

namespace {

constexpr std::size_t kSamplesPerPiece = 64;
constexpr std::size_t kMaxPieces = 1'000'000;

double circle_error(double radius, double theta) {
    const double s = std::sin(theta / 4), c = std::cos(theta / 4);
    return radius * 2.0 / 27.0 * std::pow(s, 6) / (c * c);
}

Vec2 unit(double a) {
    return {std::cos(a), std::sin(a)};
}

Vec2 bezier(const Cubic& b, double t) {
    const double u = 1 - t;
    return (u * u * u) * b.p[0] + (3 * u * u * t) * b.p[1] + (3 * u * t * t) * b.p[2] +
           (t * t * t) * b.p[3];
}

class ArcPieces {
public:
    explicit ArcPieces(const Arc& arc) : arc_(arc) {
        const Vec2 s = arc.start - arc.center, e = arc.end - arc.center;
        r0_ = std::hypot(s.x, s.y);
        r1_ = std::hypot(e.x, e.y);
        a0_ = std::atan2(s.y, s.x);
    }

    double largest_radius() const { return std::max(r0_, r1_); }

    std::vector<Cubic> build(std::size_t n) const {
        const double step = arc_.sweep / static_cast<double>(n);
        const double h = 4.0 / 3.0 * std::tan(step / 4);
        const double dr = (r1_ - r0_) / arc_.sweep;  // radius change per radian
        std::vector<Cubic> pieces;
        pieces.reserve(n);
        Vec2 from = arc_.start;
        for (std::size_t k = 0; k < n; ++k) {
            const double f0 = static_cast<double>(k) / static_cast<double>(n);
            const double f1 = static_cast<double>(k + 1) / static_cast<double>(n);
            const double b0 = a0_ + arc_.sweep * f0, b1 = a0_ + arc_.sweep * f1;
            const double q0 = r0_ + (r1_ - r0_) * f0, q1 = r0_ + (r1_ - r0_) * f1;
            const Vec2 to = k + 1 == n ? arc_.end : arc_.center + q1 * unit(b1);
            const Vec2 t0 = dr * unit(b0) + q0 * Vec2{-std::sin(b0), std::cos(b0)};
            const Vec2 t1 = dr * unit(b1) + q1 * Vec2{-std::sin(b1), std::cos(b1)};
            pieces.push_back(Cubic{{from, from + h * t0, to - h * t1, to}});
            from = to;
        }
        return pieces;
    }

    // Largest radial distance between the pieces and the arc (or spiral), sampled.
    double deviation(const std::vector<Cubic>& pieces) const {
        const double n = static_cast<double>(pieces.size());
        double worst = 0;
        for (std::size_t k = 0; k < pieces.size(); ++k) {
            for (std::size_t j = 1; j < kSamplesPerPiece; ++j) {
                const double t = static_cast<double>(j) / kSamplesPerPiece;
                const Vec2 d = bezier(pieces[k], t) - arc_.center;
                // The sample's angle, unwrapped next to where the arc is at this parameter.
                const double guess = a0_ + arc_.sweep * (static_cast<double>(k) + t) / n;
                const double angle =
                    guess + std::remainder(std::atan2(d.y, d.x) - guess, 2 * std::numbers::pi);
                const double expected = r0_ + (r1_ - r0_) * (angle - a0_) / arc_.sweep;
                // A helix's normal axis is at (k + t) / n of the rise on the piece; on the
                // helix it is at the sample's angle.
                const double axial =
                    arc_.rise * ((static_cast<double>(k) + t) / n - (angle - a0_) / arc_.sweep);
                worst = std::max(worst, std::hypot(std::hypot(d.x, d.y) - expected, axial));
            }
        }
        return worst;
    }

private:
    Arc arc_;
    double r0_ = 0, r1_ = 0, a0_ = 0;
};

}  // namespace

std::vector<Cubic> arc_to_cubics(const Arc& arc, double tolerance_mm) {
    const ArcPieces geometry(arc);
    const double turn = std::fabs(arc.sweep);
    auto n =
        static_cast<std::size_t>(std::max(1.0, std::ceil(turn / (std::numbers::pi / 2) - 1e-9)));
    // The closed form for a circle, with half the tolerance left for a spiral's extra error.
    while (circle_error(geometry.largest_radius(), turn / static_cast<double>(n)) >
           tolerance_mm / 2) {
        ++n;
    }
    while (n <= kMaxPieces) {
        std::vector<Cubic> pieces = geometry.build(n);
        if (geometry.deviation(pieces) <= tolerance_mm) return pieces;
        n += n / 2 + 1;
    }
    throw std::length_error("arc_to_cubics: arc needs more than a million pieces");
}

}  // namespace pathstream::host::gcode
