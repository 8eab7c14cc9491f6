// Cutter radius compensation (G41/G42, G41.1/G42.1) as plane geometry: the path of the tool's
// center for a programmed XY path, following LinuxCNC's interpreter (interp_convert.cc,
// convert_straight_comp1/2 and convert_arc_comp1/2). Knows nothing of the interpreter: the
// caller turns blocks into PlaneMoves and the result back into moves.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "vec2.hpp"

namespace pathstream::host::gcode {

/// One programmed (or tool center) move in the XY plane, mm. An arc turns about `center` from
/// `start` to `end`, counterclockwise when `ccw`, by the angle in (0, 2π] that takes it there
/// in that direction: a full circle when start == end. `source` is the caller's index of the
/// move (a block); moves the compensation adds carry the source of the move they belong to.
struct PlaneMove {
    enum Kind { kLine, kArc } kind = kLine;
    Vec2 start, end, center;
    bool ccw = true;
    std::size_t source = 0;
};

/// G41: the tool left of the programmed path (seen from +Z, facing along the motion);
/// G42: right of it.
enum class CompSide { kLeft, kRight };

/// The tool center path: each move starts where the one before ends.
struct CompResult {
    std::vector<PlaneMove> moves;
};

/// A path the tool cannot follow at this radius. `source` is PlaneMove::source of the move at
/// fault; what() is LinuxCNC's message for the same case.
class CompError : public std::runtime_error {
public:
    CompError(std::size_t at, const std::string& message)
        : std::runtime_error(message), source(at) {}
    std::size_t source;
};

/// The tool center path for `programmed` (the moves from G41/G42 up to G40) with a tool of
/// `radius` mm (>= 0; a negative tool table diameter is the caller's to turn into the other
/// side, as LinuxCNC does) on `side`.
///
/// - programmed[0] is the entry move. It runs from `tool_start` (where the tool's center is,
///   not offset; programmed[0].start is not used) to its end point offset by the radius to
///   `side` (LinuxCNC's comp1). Its end must be farther than the radius from tool_start.
/// - Every later move is offset by the radius to `side` and must start where the one before
///   ends (within 1e-6 mm). At a corner turning away from the tool (outside) an arc of the
///   tool radius about the programmed corner joins the two; at a corner turning toward it
///   (inside) both offset moves are cut back to where they meet. A corner whose two offset
///   points are within `tolerance` mm (>= 0) of each other counts as tangent: a straight move
///   joins them (none when they coincide). A move reversing the one before is an outside
///   corner unless the curvatures make the two offsets cross (LinuxCNC's "h" shape).
/// - A line without length (a Z-only move) keeps the tool where it is.
/// - The last move ends at the offset end of the last programmed move (the exit move after
///   G40 is the caller's).
/// radius 0: the moves as programmed, the first from tool_start.
///
/// Throws CompError for an entry too short, a concave arc of no more than the tool radius, an
/// inside corner the tool cannot reach or whose cut would run a move backwards (gouging).
/// Throws std::invalid_argument for a negative radius or tolerance or moves not joined up.
CompResult compensate(const std::vector<PlaneMove>& programmed, Vec2 tool_start, CompSide side,
                      double radius, double tolerance);

}  // namespace pathstream::host::gcode
