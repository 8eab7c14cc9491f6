// The drawings bench_plan plans: generated ones (2 axes, mm) and the repository's examples,
// read the way the CLI reads them.
#pragma once

#include <cstddef>
#include <string>

#include "pathstream/host/path.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::bench {

/// examples/machines/pen_plotter.json's values (250 mm/s, 3000 mm/s^2 per axis, 1 kHz,
/// 8 ticks per span, 1 um LSB, feed 80 mm/s, travel 200 mm/s, chord tolerance 5 um).
host::MachineProfile bench_pen_plotter();

/// Closed uniform B-spline through n points of a 7-petal rose r = 60 cos(7 t): n segments.
host::Path rose_path(std::size_t n);

/// Open uniform B-spline through n points of a smooth random walk (1.5 mm steps, heading
/// changes N(0, 0.25 rad), steered back inside a 200 mm square; seeded): n - 1 segments.
host::Path wander_path(std::size_t n);

/// Polyline of n straight segments along an Archimedean spiral (20 turns, 3 mm pitch, from
/// r = 5 mm): every vertex a small corner (0.126 rad at n = 1,000, 0.0126 at 10,000).
host::Path spiral_path(std::size_t n);

/// Polyline of n straight segments of 1-6 mm in a 200 mm square, each vertex turning by a
/// seeded uniform angle of min_turn..max_turn radians (either side).
host::Path random_polyline(std::size_t n, double min_turn, double max_turn, unsigned seed);

/// A repository drawing read as `pathstream plan FILE --order` reads it (a JobRequest with
/// default options: by extension, .csv as a closed polyline as its header asks, .ngc/.gcode
/// with the default pen mode), grouped by layer with a pause between pens, layer feeds from
/// `machine`, subpaths ordered (merge tolerance 0.01 mm, from the origin). Throws the readers'
/// errors.
host::Path read_example(const std::string& file, const host::MachineProfile& machine);

}  // namespace pathstream::bench
