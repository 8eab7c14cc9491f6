// Cutter radius compensation: the entry move and the corners between offset moves, after
// LinuxCNC's interp_convert.cc (convert_straight_comp1/2, convert_arc_comp1/2). LinuxCNC
// builds the path one block at a time, moving the end of the queued move back when the next
// block makes an inside corner; here the whole path is known, so the same cuts are made on a
// vector of tool moves.
#include "cutter_comp.hpp"

#include <algorithm>
#include <stdexcept>

#include "cutter_offset.hpp"

namespace pathstream::host::gcode {

namespace {

using namespace cutter;

constexpr const char* kArcTooSmall = "Tool radius not less than arc radius with comp";
constexpr double kJoinSlack = 1e-6;  // mm: how far apart consecutive programmed moves may be

enum class Corner { kTangent, kOutside, kInside };

// The entry line (comp1): from the tool's center to the programmed end point moved by the
// radius square to the line from the tool to that point.
ToolMove entry_line(const PlaneMove& m, Vec2 tool, double offset, double radius) {
    if (norm(m.end - tool) <= radius) {
        throw CompError(m.source,
                        "Length of cutter compensation entry move is not greater than the tool "
                        "radius");
    }
    const Vec2 t = unit(m.end - tool);
    PlaneMove line{PlaneMove::kLine, tool, m.end + offset * left(t), {}, true, m.source};
    ToolMove entry = tool_move(line);
    entry.along = t;
    return entry;
}

// The entry arc (comp1): from the tool's center to the programmed end moved by the radius
// along the arc's radius; its center on that radius, as far from both ends.
ToolMove entry_arc(const PlaneMove& m, Vec2 tool, double offset, double radius) {
    if (norm(m.end - tool) <= radius) {
        throw CompError(m.source,
                        "Radius of cutter compensation entry arc is not greater than the tool "
                        "radius");
    }
    const bool inward = (offset > 0) == m.ccw;
    if (inward && norm(m.end - m.center) <= radius) throw CompError(m.source, kArcTooSmall);
    const Vec2 end = m.end + offset * left(end_tangent(m));
    const auto center =
        line_line(end, unit(m.center - end), 0.5 * (tool + end), left(unit(end - tool)));
    // No such center when the tool's start lies on the tangent at the new end.
    if (center.empty()) throw CompError(m.source, kArcTooSmall);
    return tool_move(PlaneMove{PlaneMove::kArc, tool, end, center.front(), m.ccw, m.source});
}

// LinuxCNC tests corners by angle (TOLERANCE_CONCAVE_CORNER, 0.05 rad); here by the distance
// between the two offset points, which is what the tool skips or doubles back over.
Corner classify(Vec2 t1, double k1, Vec2 t2, double k2, double sigma, double radius,
                double tolerance) {
    const Vec2 n1 = sigma * left(t1), n2 = sigma * left(t2);
    const double slack = std::max(tolerance, kNoise);
    if (radius * norm(n2 - n1) <= slack) return Corner::kTangent;
    // A reversal has no turning side: the curvatures tell whether the offsets cross (the tool
    // sits between the two moves) or the tool goes round the tip (LinuxCNC's "h" shape).
    if (radius * norm(n2 + n1) <= slack) {
        return sigma * (k1 + k2) < -1e-12 ? Corner::kInside : Corner::kOutside;
    }
    return sigma * cross(t1, t2) > 0 ? Corner::kInside : Corner::kOutside;
}

const char* no_fit_message(const ToolMove& prev, const ToolMove& next) {
    const bool prev_arc = prev.move.kind == PlaneMove::kArc;
    const bool next_arc = next.move.kind == PlaneMove::kArc;
    if (prev_arc && next_arc) {
        return "Arc to arc motion makes a corner the compensated tool can't fit in without "
               "gouging";
    }
    if (prev_arc) {
        return "Arc to straight motion makes a corner the compensated tool can't fit in without "
               "gouging";
    }
    return "Arc move in concave corner cannot be reached by the tool without gouging";
}

class PathBuilder {
public:
    PathBuilder(double radius, double sigma, double tolerance)
        : radius_(radius), sigma_(sigma), tolerance_(tolerance) {}

    void enter(const PlaneMove& m, Vec2 tool) {
        const double offset = sigma_ * radius_;
        add(m.kind == PlaneMove::kLine ? entry_line(m, tool, offset, radius_)
                                       : entry_arc(m, tool, offset, radius_));
        // The entry line's direction is from the tool, not from the programmed start.
        tangent_ = m.kind == PlaneMove::kLine ? unit(m.end - tool) : end_tangent(m);
        curvature_ = curvature(m);
    }

    // One programmed move after the entry (comp2): its offset, joined to the path at `corner`.
    void follow(const PlaneMove& m, Vec2 corner) {
        ToolMove next = offset_move(m, sigma_ * radius_);
        if (next.stationary) {
            path_.push_back(next);  // placed in finish(), once the corner is settled
            return;
        }
        const Corner kind = classify(tangent_, curvature_, start_tangent(m), curvature(m), sigma_,
                                     radius_, tolerance_);
        if (kind == Corner::kTangent) join_tangent(next);
        if (kind == Corner::kOutside) go_round(next, corner);
        if (kind == Corner::kInside) cut_back(next, corner);
        add(next);
        tangent_ = end_tangent(m);
        curvature_ = curvature(m);
    }

    std::vector<PlaneMove> finish() const {
        std::vector<PlaneMove> moves;
        moves.reserve(path_.size());
        for (const ToolMove& t : path_) {
            moves.push_back(finished(t));
            if (t.stationary) moves.back().start = moves.back().end = moves[moves.size() - 2].end;
        }
        return moves;
    }

private:
    void add(const ToolMove& t) {
        path_.push_back(t);
        last_ = path_.size() - 1;
    }

    // Nearly in line: the offset points are at most the tolerance apart, a straight move
    // bridges them (rounding only: the next move starts where the last ends).
    void join_tangent(ToolMove& next) {
        const Vec2 end = path_[last_].move.end;
        if (norm(next.move.start - end) > kNoise) {
            path_.push_back(tool_move(
                PlaneMove{PlaneMove::kLine, end, next.move.start, {}, true, next.move.source}));
            return;
        }
        // A full circle stays one: its end goes where its start goes.
        if (next.move.kind == PlaneMove::kArc && next.move.start == next.move.end) {
            next.move.end = end;
        }
        next.move.start = end;
    }

    // Outside corner: an arc of the tool radius about the programmed corner, turning away
    // from the tool's side (clockwise for G41), as LinuxCNC inserts.
    void go_round(const ToolMove& next, Vec2 corner) {
        path_.push_back(tool_move(PlaneMove{PlaneMove::kArc, path_[last_].move.end, next.move.start,
                                            corner, sigma_ < 0, next.move.source}));
    }

    // Inside corner: both moves end where their offsets meet, the point nearest the corner.
    void cut_back(ToolMove& next, Vec2 corner) {
        ToolMove& prev = path_[last_];
        const std::vector<Vec2> points = intersections(prev, next);
        if (points.empty()) throw CompError(next.move.source, no_fit_message(prev, next));
        Vec2 best = points.front();
        for (const Vec2& p : points) {
            if (norm(p - corner) < norm(best - corner)) best = p;
        }
        trim_end(prev, best);
        trim_start(next, best);
    }

    double radius_, sigma_, tolerance_;
    std::vector<ToolMove> path_;
    std::size_t last_ = 0;  ///< the last move in path_ with length (not a join)
    Vec2 tangent_;          ///< the programmed direction where the last move ended
    double curvature_ = 0;  ///< and its curvature there
};

}  // namespace

CompResult compensate(const std::vector<PlaneMove>& programmed, Vec2 tool_start, CompSide side,
                      double radius, double tolerance) {
    if (!(radius >= 0) || !(tolerance >= 0)) {
        throw std::invalid_argument("compensate: radius and tolerance must be >= 0");
    }
    for (std::size_t i = 1; i < programmed.size(); ++i) {
        if (norm(programmed[i].start - programmed[i - 1].end) > kJoinSlack) {
            throw std::invalid_argument("compensate: a move does not start where the last ends");
        }
    }
    if (programmed.empty()) return {};
    if (radius == 0) {
        CompResult result{programmed};
        result.moves.front().start = tool_start;
        return result;
    }
    PathBuilder builder(radius, side == CompSide::kLeft ? 1.0 : -1.0, tolerance);
    builder.enter(programmed.front(), tool_start);
    for (std::size_t i = 1; i < programmed.size(); ++i) {
        builder.follow(programmed[i], programmed[i - 1].end);
    }
    return {builder.finish()};
}

}  // namespace pathstream::host::gcode
