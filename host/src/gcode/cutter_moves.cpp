// Cutter radius compensation in the reader (docs/formats-gcode.md, "Cutter radius
// compensation"): G41/G42 collect the programmed moves in the plane (G17, G18) up to G40,
// cutter_comp.cpp turns them into the tool center's path, and the moves are made along it with
// every other axis as programmed.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "arc.hpp"
#include "cutter_comp.hpp"
#include "interpreter.hpp"

namespace pathstream::host::gcode {

void Interpreter::cutter_mode(const Command& c) {
    if (!c.cutter_comp) return;
    if (*c.cutter_comp == CutterComp::kOff) {
        if (comp_) comp_flush();
        return;
    }
    const SourceLocation at = c.cutter_comp_at;
    if (comp_) fail(at, "cutter radius compensation is on already (give G40 first)");
    // As LinuxCNC: G17 (a mill) and G18 (a lathe's XZ), the side seen from the plane's normal.
    if (plane_.normal == kX) fail(at, "cutter radius compensation needs G17 or G18, not G19");
    if (inverse_time_) fail(at, "cutter radius compensation with inverse time feed (G93)");
    const bool left =
        *c.cutter_comp == CutterComp::kLeft || *c.cutter_comp == CutterComp::kLeftDiameter;
    const bool given_diameter =
        *c.cutter_comp == CutterComp::kLeftDiameter || *c.cutter_comp == CutterComp::kRightDiameter;
    const Word* d = c.value('D');
    double diameter = 0;
    if (given_diameter) {
        // G41.1 / G42.1: D is the diameter itself, in the program's units.
        if (!d) fail(at, "G41.1 and G42.1 need D (the tool diameter)");
        diameter = length(*d);
    } else {
        // G41 / G42: D names a tool of the table; without D, the tool M6 loaded.
        if (d && (d->value != std::floor(d->value) || d->value < 0)) {
            fail(d->at, "D must be a whole tool number >= 0");
        }
        const long tool =
            d && d->value > 0 ? static_cast<long>(d->value) : std::max(loaded_tool_, 0L);
        if (tool > 0) {
            if (tools_.empty()) fail(at, "G41/G42: no tool table (give one with --tool-table)");
            const ToolEntry* entry = tools_.find(tool);
            if (!entry) {
                fail(d ? d->at : at, "G41/G42: tool " + std::to_string(tool) +
                                         " is not in the tool table " + tools_.source());
            }
            diameter = entry->diameter;
        }  // tool 0 (none loaded, D0): no tool, radius 0, as LinuxCNC
    }
    // As LinuxCNC, a negative diameter puts the tool on the other side.
    CompState state;
    state.side = (left == (diameter >= 0)) ? CompSide::kLeft : CompSide::kRight;
    state.radius = std::fabs(diameter) / 2;
    state.start = pos_;
    state.at = at;
    comp_ = std::move(state);
}

void Interpreter::comp_refuse(const Command& c) const {
    if (!comp_) return;
    const char* what = nullptr;
    SourceLocation at = c.start;
    if (c.plane) what = "a plane change";
    if (c.non_modal != NonModal::kNone && c.non_modal != NonModal::kMachineCoords) {
        what = "G4, G10, G28, G30 or G92";
        at = c.non_modal_at;
    }
    if (c.coordinate_system) what = "a coordinate system change";
    if (c.tool_length) what = "a tool length offset change";
    if (c.pause || c.tool_change) what = "a pause or tool change";
    if (c.inverse_time && *c.inverse_time) what = "inverse time feed (G93)";
    if (c.motion && *c.motion != Motion::kRapid && *c.motion != Motion::kLine &&
        *c.motion != Motion::kArcCw && *c.motion != Motion::kArcCcw && !c.end_program) {
        what = "this motion (only G0, G1, G2 and G3)";
        at = c.motion_at;
    }
    if (what) {
        fail(at, std::string(what) +
                     " while cutter radius compensation is on (give G40 first; it began at "
                     "line " +
                     std::to_string(comp_->at.line) + ")");
    }
}

void Interpreter::comp_add(PlaneMove::Kind kind, const Arc* arc, bool rapid, const Axes& to,
                           SourceLocation at) {
    CompMove m;
    m.plane.kind = kind;
    m.plane.start = in_plane(pos_, plane_);
    m.plane.end = in_plane(to, plane_);
    if (arc) {
        m.plane.center = arc->center;
        m.plane.ccw = arc->sweep > 0;
    }
    m.plane.source = comp_->moves.size();
    m.from = pos_;
    m.to = to;
    m.rapid = rapid;
    m.at = at;
    if (!rapid) {
        const std::vector<Piece> programmed{line_piece(pos_, to)};
        m.feed = move_feed(programmed, at);  // F is a speed: the offset path keeps it
    }
    comp_->moves.push_back(m);
    pos_ = to;  // the programmed point: G91 and arcs count from it
}

void Interpreter::comp_flush() {
    CompState state = std::move(*comp_);
    comp_.reset();
    std::vector<PlaneMove> programmed;
    for (const CompMove& m : state.moves) programmed.push_back(m.plane);
    pos_ = state.start;
    if (programmed.empty()) return;
    CompResult result;
    try {
        result = compensate(programmed, in_plane(state.start, plane_), state.side, state.radius,
                            options_.arc_tolerance_mm);
    } catch (const CompError& e) {
        fail(state.moves.at(e.source).at, e.what());
    }
    std::size_t r = 0;
    for (std::size_t k = 0; k < state.moves.size(); ++k) {
        const CompMove& m = state.moves[k];
        std::vector<const PlaneMove*> own;
        while (r < result.moves.size() && result.moves[r].source == k)
            own.push_back(&result.moves[r++]);
        std::vector<Cubic> plane;
        for (const PlaneMove* t : own) {
            if (t->kind == PlaneMove::kLine) {
                plane.push_back(line_piece(t->start, t->end));
                continue;
            }
            double sweep = std::atan2(t->end.y - t->center.y, t->end.x - t->center.x) -
                           std::atan2(t->start.y - t->center.y, t->start.x - t->center.x);
            if (t->ccw && sweep <= 0) sweep += 2 * std::numbers::pi;
            if (!t->ccw && sweep >= 0) sweep -= 2 * std::numbers::pi;
            for (const Cubic& c : arc_to_cubics(Arc{t->start, t->end, t->center, sweep},
                                                options_.arc_tolerance_mm)) {
                plane.push_back(c);
            }
        }
        Axes to = m.to;
        if (!plane.empty()) {
            to[plane_.first] = plane.back().p[3].x;
            to[plane_.second] = plane.back().p[3].y;
        } else {
            to[plane_.first] = pos_[plane_.first];
            to[plane_.second] = pos_[plane_.second];
            if (to == pos_) continue;
            plane.push_back(line_piece(in_plane(pos_, plane_), in_plane(pos_, plane_)));
        }
        // Every other axis moves linearly along the move's own length in the plane.
        std::vector<double> lengths;
        double total = 0;
        for (const Cubic& c : plane) {
            const double l = std::hypot(c.p[3].x - c.p[0].x, c.p[3].y - c.p[0].y) +
                             std::hypot(c.p[1].x - c.p[0].x, c.p[1].y - c.p[0].y) * 1e-9;
            lengths.push_back(l);
            total += l;
        }
        std::vector<Piece> pieces;
        double done = 0;
        for (std::size_t i = 0; i < plane.size(); ++i) {
            Piece piece;
            for (int j = 0; j < 4; ++j) {
                const double f = total > 0 ? (done + lengths[i] * j / 3.0) / total
                                           : (static_cast<double>(i) + j / 3.0) /
                                                 static_cast<double>(plane.size());
                for (std::size_t a = 0; a < kAxisCount; ++a)
                    piece.p[j][a] = pos_[a] + f * (to[a] - pos_[a]);
                piece.p[j][plane_.first] = plane[i].p[j].x;
                piece.p[j][plane_.second] = plane[i].p[j].y;
            }
            if (i > 0) piece.p[0] = pieces.back().p[3];
            if (i == 0) piece.p[0] = pos_;
            if (i + 1 == plane.size()) piece.p[3] = to;
            done += lengths[i];
            pieces.push_back(piece);
        }
        if (m.rapid) {
            if (machine()) {
                follow(pieces, false, to, m.at);
            } else {
                runs_.lift();
                last_move_drew_ = false;
                pos_ = to;
            }
        } else {
            follow(pieces, pen_down(pos_[kZ], to[kZ]), to, m.at, m.feed);
        }
    }
}

}  // namespace pathstream::host::gcode
