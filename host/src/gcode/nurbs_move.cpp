// G5.2/G5.3: NURBS curves in the XY plane as LinuxCNC reads them (docs/formats-gcode.md,
// "NURBS").
#include <cmath>
#include <stdexcept>

#include "../nurbs/nurbs.hpp"
#include "interpreter.hpp"

namespace pathstream::host::gcode {

namespace {
constexpr int kDefaultOrder = 3;  // LinuxCNC: L omitted is order 3 (quadratic)

double weight(const Word* p) {
    return p ? p->value : 1.0;
}
}  // namespace

// As LinuxCNC's convert_nurbs: the first block of a curve also takes the current point (its
// weight from a P without X Y); an L above 3 on any block sets the order, lower ones do not.
void Interpreter::nurbs_point(const Command& c, const Axes& to3, SourceLocation at) {
    if (plane_.normal != kZ) fail(at, "G5.2 needs the XY plane (G17)");
    const Vec2 to = in_plane(to3, kPlaneXY);
    const Word *x = c.value('X'), *y = c.value('Y'), *p = c.value('P'), *l = c.value('L');
    if (const Word* z = c.value('Z')) fail(z->at, "Z is not allowed with G5.2 (XY plane only)");
    if (p && !(p->value > 0)) fail(p->at, "G5.2 weight P must be positive");
    if (nurbs_.empty()) {
        nurbs_order_ = kDefaultOrder;
        nurbs_.push_back({in_plane(pos_, kPlaneXY), x || y ? 1.0 : weight(p)});
    } else if (!x && !y) {
        fail(at, "a G5.2 control point needs X and Y (P alone weighs only the start point)");
    }
    if (l) {
        if (l->value != std::floor(l->value) || l->value < 0 || l->value > nurbs::kMaxDegree + 1) {
            fail(l->at, "G5.2 order L must be a whole number up to " +
                            std::to_string(nurbs::kMaxDegree + 1) +
                            " (degree + 1; 3 or less leaves the order at 3)");
        }
        if (l->value > kDefaultOrder) nurbs_order_ = static_cast<int>(l->value);
    }
    if (!x && !y) return;
    if (!x || !y) fail(at, "a G5.2 control point needs both X and Y");
    nurbs_.push_back({to, weight(p)});
    // The curve is drawn at G5.3 from its first point: the position moves on now.
    nurbs_start_ = nurbs_.size() == 2 ? pos_ : nurbs_start_;
    pos_[kX] = to.x;
    pos_[kY] = to.y;
}

void Interpreter::nurbs_end(SourceLocation at) {
    nurbs::Nurbs curve;
    curve.degree = nurbs_order_ - 1;
    for (const NurbsPoint& point : nurbs_) {
        curve.points.push_back({point.at.x, point.at.y});
        curve.weights.push_back(point.weight);
    }
    if (nurbs_.size() < static_cast<std::size_t>(nurbs_order_)) {
        fail(nurbs_at_, "G5.2 curve of order L" + std::to_string(nurbs_order_) +
                            " needs at least " + std::to_string(nurbs_order_) +
                            " control points (the start point included), got " +
                            std::to_string(nurbs_.size()));
    }
    curve.knots = nurbs::clamped_uniform_knots(curve.points.size(), curve.degree);
    std::vector<PathPoint> chain;
    try {
        chain = nurbs::nurbs_to_bezier(curve, options_.arc_tolerance_mm);
    } catch (const std::length_error& e) {
        fail(at, e.what());
    }
    std::vector<Cubic> pieces;
    for (std::size_t k = 0; k + 3 < chain.size(); k += 3) {
        Cubic piece;
        for (std::size_t i = 0; i < 4; ++i) piece.p[i] = Vec2{chain[k + i][0], chain[k + i][1]};
        pieces.push_back(piece);
    }
    const Axes end = pos_;
    nurbs_.clear();
    pos_ = nurbs_start_;  // lift() runs from the curve's start
    follow(lift(pieces, end), pen_down(pos_[kZ], pos_[kZ]), end, nurbs_at_);
}

}  // namespace pathstream::host::gcode
