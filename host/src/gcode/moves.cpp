// Moves into pieces: the feed of a feed move (F, G93, LinuxCNC's rule for rotary axes), plane
// pieces lifted into every axis, and drawn or travel runs (docs/formats-gcode.md, "Moves").
#include <cmath>

#include "interpreter.hpp"

namespace pathstream::host::gcode {

void Interpreter::travel(const Axes& to, SourceLocation at) {
    if (comp_) {
        comp_add(PlaneMove::kLine, nullptr, true, to, at);
        return;
    }
    if (machine()) {
        follow({line_piece(pos_, to)}, false, to, at);
        return;
    }
    runs_.lift();
    last_move_drew_ = false;
    pos_ = to;
}

double Interpreter::move_feed(const std::vector<Piece>& pieces, SourceLocation at) const {
    // Chord lengths: the path's feed is along all its axes, F along X Y Z when they move
    // (LinuxCNC), else along U V W, else A B C (degrees per minute).
    double all = 0, xyz = 0, uvw = 0, abc = 0;
    for (const Piece& piece : pieces) {
        for (int k = 0; k < 3; ++k) {
            double s_all = 0, s_xyz = 0, s_uvw = 0, s_abc = 0;
            for (std::size_t a = 0; a < kAxisCount; ++a) {
                if (!on_path(a)) continue;
                const double d = piece.p[k + 1][a] - piece.p[k][a];
                s_all += d * d;
                (a < 3 ? s_xyz : is_rotary(a) ? s_abc : s_uvw) += d * d;
            }
            all += std::sqrt(s_all);
            xyz += std::sqrt(s_xyz);
            uvw += std::sqrt(s_uvw);
            abc += std::sqrt(s_abc);
        }
    }
    if (inverse_time_) {
        if (inverse_minutes_ <= 0) fail(at, "G93 (inverse time) needs F on every feed move");
        return all / (60 * inverse_minutes_);
    }
    if (feed_ <= 0) {
        if (!machine()) return 0;  // a plotter: the profile's feed
        fail(at, "feed move with no feed rate (give F first)");
    }
    const double primary = xyz > 1e-9 ? xyz : uvw > 1e-9 ? uvw : abc;
    // F is in the program's length unit along X Y Z and U V W, in degrees along A B C.
    const double feed = xyz > 1e-9 || uvw > 1e-9 || abc <= 1e-9 ? feed_ * scale() : feed_;
    if (primary <= 1e-9 || std::fabs(all - primary) <= 1e-12 * all) return feed;
    return feed * all / primary;
}

std::vector<Piece> Interpreter::lift(const std::vector<Cubic>& pieces, const Axes& to) const {
    std::vector<Piece> out;
    out.reserve(pieces.size());
    const double n = static_cast<double>(pieces.size());
    for (std::size_t k = 0; k < pieces.size(); ++k) {
        Piece piece;
        for (int i = 0; i < 4; ++i) {
            const double f = (static_cast<double>(k) + i / 3.0) / n;
            for (std::size_t a = 0; a < kAxisCount; ++a) {
                piece.p[i][a] = i == 3 && k + 1 == pieces.size() ? to[a]
                                : i == 0 && k == 0               ? pos_[a]
                                                                 : pos_[a] + f * (to[a] - pos_[a]);
            }
            piece.p[i][plane_.first] = pieces[k].p[i].x;
            piece.p[i][plane_.second] = pieces[k].p[i].y;
        }
        if (k > 0) piece.p[0] = out.back().p[3];
        out.push_back(piece);
    }
    return out;
}

void Interpreter::follow(const std::vector<Piece>& pieces, bool down, const Axes& to,
                         SourceLocation at, std::optional<double> fixed_feed) {
    for (const Piece& piece : pieces) {
        for (const Axes& p : piece.p) check_point(p, at);
    }
    if (down) {
        const double feed = fixed_feed ? *fixed_feed : move_feed(pieces, at);
        for (const Piece& piece : pieces) runs_.draw(piece, feed, at, *file_);
        runs_.end_block();
    } else if (machine()) {
        for (const Piece& piece : pieces) runs_.travel(piece, options_.rapid_feed, at, *file_);
    } else {
        runs_.lift();
    }
    last_move_drew_ = down;
    pos_ = to;
}

void Interpreter::line(const Axes& to, SourceLocation at) {
    if (comp_) {
        comp_add(PlaneMove::kLine, nullptr, false, to, at);
        return;
    }
    follow({line_piece(pos_, to)}, pen_down(pos_[kZ], to[kZ]), to, at);
}

}  // namespace pathstream::host::gcode
