// Contour error: how far the tool is from the path it was asked to follow, the polyline of the
// planned setpoints (docs/simulator.md, "Contour error").
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace pathstream::sim {

/// Setpoint ticks a tool point is compared with ahead of its own tick.
inline constexpr std::uint64_t kContourAheadTicks = 64;

/// The path and the tool around the worst contour error, for a zoomed plot.
struct ContourWindow {
    std::size_t axes = 0;
    std::vector<double> path_mm;        ///< the reference polyline's vertices, row-major
    std::vector<double> tool_mm;        ///< the tool's position at consecutive ticks, row-major
    std::uint64_t first_tool_tick = 0;  ///< tick of tool_mm's first row
};

/// The contour error over a run.
struct ContourError {
    double max_mm = 0;                ///< largest distance
    double rms_mm = 0;                ///< RMS over every tick
    std::uint64_t max_tick = 0;       ///< tick of the largest distance
    std::vector<double> max_tool_mm;  ///< tool position per axis at that tick (empty: no tick)
    std::vector<double> max_path_mm;  ///< the nearest point of the path to it
    std::uint64_t back_ticks = 0;     ///< the window: setpoint ticks behind the tool's tick
    std::uint64_t ahead_ticks = 0;    ///< and ahead of it
    ContourWindow window;             ///< +/- back_ticks around max_tick
};

/// Setpoint ticks behind a tool point to compare it with: 64 plus four times the plant's lag
/// behind a ramp (`lag_seconds`, e.g. 2 zeta / omega for the servo) in ticks, at most 4096.
std::uint64_t contour_back_ticks(double tick_hz, double lag_seconds);

/// Measures the contour error tick by tick in bounded memory. The reference path is the
/// polyline through the setpoints of every tick (repeated ones are one vertex). The tool's
/// point at tick j is compared with the part of it from the setpoint in effect at tick
/// j - back_ticks to the one of tick j + ahead_ticks: its distance is the smallest Euclidean
/// distance over all axes to a vertex or segment there. So it is computed ahead_ticks late
/// (finish() computes the last ones). Memory O((2 back + ahead) axes).
class ContourErrorMeter {
public:
    /// `axes` 1..8, `back_ticks` >= 1. Throws std::invalid_argument otherwise.
    ContourErrorMeter(std::size_t axes, std::uint64_t back_ticks,
                      std::uint64_t ahead_ticks = kContourAheadTicks);

    /// The next tick (in order, from 0): the reference setpoint and the tool's position, mm.
    void add(const double* reference_mm, const double* tool_mm);
    /// After the last tick: the figures. Call once.
    ContourError finish();

private:
    void evaluate(std::uint64_t tick);
    void scan(std::uint64_t first, std::uint64_t last);  // vertices first..last and segments
    void snapshot(std::uint64_t tick);
    const double* vertex(std::uint64_t index) const;  // by vertex number, must be kept
    std::uint64_t vertex_tick(std::uint64_t index) const;
    const double* tool(std::uint64_t tick) const;

    std::size_t axes_;
    std::uint64_t back_, ahead_;
    std::uint64_t ticks_ = 0;     // ticks added
    std::uint64_t vertices_ = 0;  // vertices added
    std::uint64_t vertex_capacity_, tool_capacity_;
    std::vector<double> vertex_mm_;  // ring of vertices
    std::vector<std::uint64_t> vertex_ticks_;
    std::vector<double> tool_mm_;  // ring of tool points by tick
    // Blocks of 16 vertices (and the first of the next: their segments): bounding boxes, so
    // that a block farther than the nearest point found so far is skipped whole.
    std::uint64_t block_capacity_;
    std::vector<double> block_lo_, block_hi_;
    std::uint64_t start_ = 0;  // the vertex in effect at the window's first tick
    std::uint64_t own_ = 0;    // the vertex in effect at the tool's tick
    // The evaluation under way: its tool point, the best squared distance, where.
    const double* point_ = nullptr;
    double best_ = 0;
    std::uint64_t best_vertex_ = 0;
    double best_t_ = 0;  // along the segment from best_vertex_ (0: the vertex)
    double sum_squares_ = 0;
    bool pending_ = false;  // the window around max_tick is still to be taken
    ContourError r_;
};

}  // namespace pathstream::sim
