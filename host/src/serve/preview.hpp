// What the page draws before a run: the planned path to scale, its timing and its figures.
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "pathstream/host/path.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host::serve {

/// How finely the preview follows the plan.
struct PreviewOptions {
    /// mm: consecutive span end points within this of the chord between two kept vertices are
    /// merged into one straight piece (a straight line planned as 200 spans is one piece).
    double tolerance_mm = 0.01;
    std::size_t speed_samples = 1200;  ///< at most this many points on the speed plot
};

/// The plan as the page shows it, one JSON document:
///  summary: the same figures and keys as `pathstream plan --json` (duration_s, ticks,
///    tick_hz, spans, pen_changes, pauses, layers, drawn_length_mm, travel_length_mm) and
///    subpaths (the pen-down subpaths planned);
///  work_area: the machine's x-y travel box in mm, or null;
///  path: parallel arrays x, y (mm), tick (the plan's tick at that vertex), pen (1 when
///    the piece ending at the vertex draws) and layer (the index in summary.layers, which
///    lists every layer of the drawing whether chosen or not, of the subpath that piece
///    belongs to; 0 without layers), from the first span's start point through every span's
///    end point, merged as `options` says (never across a change of pen or layer);
///  speed: t (s) and v (mm/s), the fastest span speed in each of up to speed_samples bins;
///  pauses: the ticks of the programmed pauses.
/// A machine with axes named x, y and z (xyz_axes: a router) previews in 3-D: the path's x, y
/// and a third array z are those axes (merged within the tolerance in 3-D, speeds over all
/// three), and `view` says how the page shows them: projection "isometric" (isometric()),
/// axes (the machine's indexes of x, y, z) and box (their travel, x_min .. z_max, or null).
/// Other machines' documents have no `view` and no z: the page's 2-D view of axes 0 and 1.
/// Cost: one pass over the spans (a few vertices' work per span). Any thread.
nlohmann::ordered_json preview_json(const Plan& plan, const Path& path,
                                    const MachineProfile& machine,
                                    const PreviewOptions& options = {});

/// preview_json's document made from the spans as they come (a streamed plan), without the
/// plan: memory O(kept vertices + speed bins), not O(spans). The total is not known until the
/// end, so a span's speed goes to fine bins of a width that doubles as the job grows (at least
/// 2 speed_samples of them); each of the document's bins then takes the fastest fine bin that
/// starts in it (preview_json, which knows the total, bins each span exactly). Any thread.
class PreviewRecorder {
public:
    PreviewRecorder(const Path& path, const MachineProfile& machine,
                    const PreviewOptions& options = {});
    ~PreviewRecorder();
    PreviewRecorder(const PreviewRecorder&) = delete;
    PreviewRecorder& operator=(const PreviewRecorder&) = delete;
    void span(const CoreSpan& span);
    void pause(std::uint64_t tick) { pauses_.push_back(tick); }
    /// The document; `duration_s` and the counts from the plan's totals.
    nlohmann::ordered_json finish(double duration_s, std::uint64_t total_ticks,
                                  std::size_t pen_changes, double drawn_length_mm,
                                  double travel_length_mm);

private:
    friend nlohmann::ordered_json preview_json(const Plan&, const Path&, const MachineProfile&,
                                               const PreviewOptions&);
    struct State;
    std::unique_ptr<State> state_;
    std::vector<std::uint64_t> pauses_;
};

}  // namespace pathstream::host::serve
