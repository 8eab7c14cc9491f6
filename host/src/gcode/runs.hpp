// Collects the pieces of moves into subpaths: one open subpath per maximal run of pen-down
// moves with one feed and one path control mode (and, on a machine, per run of rapids: a
// travel subpath), a polyline while the run has only line pieces, else a Bezier chain.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "axes.hpp"
#include "pathstream/host/path.hpp"

namespace pathstream::host::gcode {

class RunBuilder {
public:
    /// `path_axes`: the G-code axis index of each path axis, in path order ({kX, kY} for a
    /// plotter, {kX, kY, kZ} for a router). `max_pieces`: at most this many pieces in all,
    /// which bounds the memory a hostile program can take.
    RunBuilder(std::vector<std::size_t> path_axes, std::size_t max_pieces)
        : path_axes_(std::move(path_axes)), max_pieces_(max_pieces) {}

    /// Appends a pen-down piece drawn at `feed_mm_s` (0: the machine's feed). A piece whose
    /// four points are all equal is dropped. The piece starts a new subpath (located at `at`)
    /// when no run is open or when the open run has a different feed; otherwise it must start
    /// where the run ends. Throws InputError at `at` (naming `file`) past max_pieces.
    void draw(const Piece& piece, double feed_mm_s, SourceLocation at, const std::string& file);
    /// As draw, for a rapid: the piece joins (or starts) a travel run (Subpath::travel).
    void travel(const Piece& piece, double feed_mm_s, SourceLocation at, const std::string& file);

    /// Ends the open run, if any (pen up).
    void lift();

    /// The path control mode for pieces drawn from now on (G61, G61.1, G64 [P]): a run has one,
    /// so a change within a run starts a new subpath where it ends, as a feed change does.
    /// `blend_tolerance_mm`: G64 P in mm (0: none given).
    void set_corners(CornerMode mode, double blend_tolerance_mm) {
        corner_mode_ = mode;
        blend_tolerance_ = mode == CornerMode::kBlend ? blend_tolerance_mm : 0;
    }
    CornerMode corner_mode() const { return corner_mode_; }
    double blend_tolerance() const { return blend_tolerance_; }
    /// A block's pieces are drawn: in exact stop mode (G61.1) the motion rests where it ended.
    void end_block();

    /// The next subpath started gets Subpath::pause_before (M0, M1), held with the machine
    /// functions in force now (Subpath::pause_outputs).
    void pause_next(std::string note = {}) {
        pause_next_ = true;
        pause_note_ = std::move(note);
        pause_outputs_ = outputs_;
    }
    /// The machine functions (kOutputMachineMask bits) of what is drawn from here on: a change
    /// ends the open run, so that the planner switches them where the motion rests.
    void set_outputs(std::uint8_t outputs) {
        if (outputs == outputs_) return;
        close_run();
        outputs_ = outputs;
    }
    std::uint8_t outputs() const { return outputs_; }
    /// The next subpath started rests `seconds` more at its start (G4), pen down or up.
    void dwell_next(double seconds, bool pen_down) {
        dwell_next_ += seconds;
        dwell_pen_down_ = pen_down;
    }
    /// Pieces drawn so far.
    std::size_t pieces() const { return pieces_; }

    /// The subpaths drawn so far (open, path_axes coordinates; kPolyline of the piece ends where
    /// every piece is line_piece of its ends, else kBezier with 3k + 1 points); ends the open run.
    std::vector<Subpath> finish();

private:
    void add(const Piece& piece, double feed_mm_s, bool travel, SourceLocation at,
             const std::string& file);
    PathPoint point(const Axes& a) const;

    std::vector<std::size_t> path_axes_;
    std::size_t max_pieces_;
    std::vector<Subpath> done_;
    bool open_ = false;
    bool pause_next_ = false;
    std::string pause_note_;
    std::uint8_t outputs_ = 0, pause_outputs_ = 0;
    double dwell_next_ = 0;
    bool dwell_pen_down_ = false;
    std::size_t pieces_ = 0;
    CornerMode corner_mode_ = CornerMode::kBlend;
    double blend_tolerance_ = 0;

    /// Ends the open run: a rest recorded at its very end is no joint.
    void close_run();
};

}  // namespace pathstream::host::gcode
