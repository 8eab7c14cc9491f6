// Collects the pieces of pen-down moves into subpaths: one open subpath per maximal run of
// pen-down moves with one feed, a polyline while the run has only line pieces, else a Bezier
// chain.
#pragma once

#include <string>
#include <vector>

#include "pathstream/host/path.hpp"
#include "vec2.hpp"

namespace pathstream::host::gcode {

class RunBuilder {
public:
    /// At most this many pieces in all: bounds the memory a hostile program can take.
    static constexpr std::size_t kMaxPieces = 2'000'000;

    /// Appends a pen-down piece drawn at `feed_mm_s` (0: the machine's feed). A piece whose
    /// four points are all equal is dropped. The piece starts a new subpath (located at `at`)
    /// when no run is open or when the open run has a different feed; otherwise it must start
    /// where the run ends. Throws InputError at `at` (naming `file`) past kMaxPieces.
    void draw(const Cubic& piece, double feed_mm_s, SourceLocation at, const std::string& file);

    /// Ends the open run, if any (pen up).
    void lift();

    /// The next subpath started gets Subpath::pause_before (M0, M1).
    void pause_next() { pause_next_ = true; }
    /// The next subpath started rests `seconds` more at its start (G4), pen down or up.
    void dwell_next(double seconds, bool pen_down) {
        dwell_next_ += seconds;
        dwell_pen_down_ = pen_down;
    }
    /// Pieces drawn so far.
    std::size_t pieces() const { return pieces_; }

    /// The subpaths drawn so far (open, 2 axes; kPolyline of the piece ends where every piece
    /// is line_piece of its ends, else kBezier with 3k + 1 points); ends the open run.
    std::vector<Subpath> finish();

private:
    std::vector<Subpath> done_;
    bool open_ = false;
    bool pause_next_ = false;
    double dwell_next_ = 0;
    bool dwell_pen_down_ = false;
    std::size_t pieces_ = 0;
};

}  // namespace pathstream::host::gcode
