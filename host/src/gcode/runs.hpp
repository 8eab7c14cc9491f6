// Collects the pieces of pen-down moves into subpaths: one open Bezier chain per maximal run
// of pen-down moves with one feed.
#pragma once

#include <vector>

#include "pathstream/host/path.hpp"
#include "vec2.hpp"

namespace pathstream::host::gcode {

class RunBuilder {
public:
    /// Appends a pen-down piece drawn at `feed_mm_s` (0: the machine's feed). A piece whose
    /// four points are all equal is dropped. The piece starts a new subpath (located at `at`)
    /// when no run is open or when the open run has a different feed; otherwise it must start
    /// where the run ends.
    void draw(const Cubic& piece, double feed_mm_s, SourceLocation at);

    /// Ends the open run, if any (pen up).
    void lift();

    /// The subpaths drawn so far (kBezier, open, 3k + 1 points, 2 axes); ends the open run.
    std::vector<Subpath> finish();

private:
    std::vector<Subpath> done_;
    bool open_ = false;
};

}  // namespace pathstream::host::gcode
