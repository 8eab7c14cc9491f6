#include "preview.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "pathstream/host/layers.hpp"
#include "pathstream/host/placement.hpp"

namespace pathstream::host::serve {
namespace {

struct Vertex {
    double x = 0, y = 0;
    std::uint64_t tick = 0;
    bool pen = false;
    std::size_t layer = 0;  ///< Path::layers index of the subpath the piece ending here belongs to
};

// Distance of p from the line through a and b (from a, when they coincide).
double off_chord(const Vertex& a, const Vertex& b, const Vertex& p) {
    const double dx = b.x - a.x, dy = b.y - a.y;
    const double length = std::hypot(dx, dy);
    if (length < 1e-12) return std::hypot(p.x - a.x, p.y - a.y);
    return std::fabs(dx * (p.y - a.y) - dy * (p.x - a.x)) / length;
}

// Keeps the vertices that the tolerance needs: a run from the last kept vertex grows while
// every point in it stays within `tolerance` of the chord and the pen stays the same; the
// runs are bounded so that a long gentle curve costs a fixed amount of work per vertex.
class Simplifier {
public:
    explicit Simplifier(double tolerance) : tolerance_(tolerance) {}

    void add(const Vertex& v) {
        if (kept_.empty()) {
            kept_.push_back(v);
            return;
        }
        if (!run_.empty() && (v.pen != run_.front().pen || v.layer != run_.front().layer ||
                              run_.size() >= kMaxRun || !fits(v))) {
            kept_.push_back(run_.back());
            run_.clear();
        }
        run_.push_back(v);
    }

    std::vector<Vertex> finish() {
        if (!run_.empty()) kept_.push_back(run_.back());
        run_.clear();
        return std::move(kept_);
    }

private:
    static constexpr std::size_t kMaxRun = 64;

    bool fits(const Vertex& v) const {
        const Vertex& a = kept_.back();
        if (std::hypot(v.x - a.x, v.y - a.y) < std::hypot(run_.back().x - a.x, run_.back().y - a.y))
            return false;
        return std::all_of(run_.begin(), run_.end(),
                           [&](const Vertex& p) { return off_chord(a, v, p) <= tolerance_; });
    }

    double tolerance_;
    std::vector<Vertex> kept_, run_;
};

// v to `digits` decimals, as the nearest double to that decimal (it prints as written).
double rounded(double v, int digits) {
    const double scale = std::pow(10.0, digits);
    return std::round(v * scale) / scale;
}

}  // namespace

nlohmann::ordered_json preview_json(const Plan& plan, const Path& path,
                                    const MachineProfile& machine, const PreviewOptions& options) {
    const double mm = machine.mm_per_lsb;
    const std::size_t ax = machine.axes.size();
    Simplifier simplifier(options.tolerance_mm);
    std::set<std::size_t> drawn_subpaths;
    std::uint64_t tick = 0;
    // Speed bins over the plan's duration: the fastest span (its mean speed) in each.
    const std::size_t bins =
        std::max<std::size_t>(1, std::min(options.speed_samples, plan.spans.size()));
    std::vector<double> bin_speed(bins, 0.0);
    const double total = std::max<double>(1, static_cast<double>(plan.total_ticks));
    for (std::size_t i = 0; i < plan.spans.size(); ++i) {
        const CoreSpan& s = plan.spans[i];
        // The planner's spans are Hermite (P0, P1, T0, T1): P0 where it starts, P1 where it ends.
        const std::size_t layer =
            s.subpath < path.subpaths.size() ? path.subpaths[s.subpath].layer : 0;
        if (i == 0)
            simplifier.add(
                {s.control.at(0)[0] * mm, ax > 1 ? s.control.at(1)[0] * mm : 0.0, 0, false, layer});
        const double dx = (s.control.at(0)[1] - s.control.at(0)[0]) * mm;
        const double dy = ax > 1 ? (s.control.at(1)[1] - s.control.at(1)[0]) * mm : 0.0;
        const std::size_t bin =
            std::min(bins - 1, static_cast<std::size_t>(static_cast<double>(tick) / total *
                                                        static_cast<double>(bins)));
        bin_speed[bin] = std::max(bin_speed[bin], std::hypot(dx, dy) * machine.tick_hz / s.ticks);
        tick += s.ticks;
        if (s.pen_down) drawn_subpaths.insert(s.subpath);
        simplifier.add({s.control.at(0)[1] * mm, ax > 1 ? s.control.at(1)[1] * mm : 0.0, tick,
                        s.pen_down, layer});
    }
    const std::vector<Vertex> vertices = simplifier.finish();

    nlohmann::ordered_json summary;
    summary["duration_s"] = plan.duration;
    summary["ticks"] = plan.total_ticks;
    summary["tick_hz"] = machine.tick_hz;
    summary["spans"] = plan.spans.size();
    summary["subpaths"] = drawn_subpaths.size();
    summary["pen_changes"] = plan.pen.size();
    summary["pauses"] = plan.pauses.size();
    summary["layers"] = layers_json(path);
    summary["drawn_length_mm"] = plan.path_length;
    summary["travel_length_mm"] = plan.travel_length;
    summary["vertices"] = vertices.size();

    nlohmann::ordered_json out;
    out["summary"] = summary;
    if (const auto area = work_area(machine)) {
        out["work_area"] = {{"x_min", area->x_min},
                            {"y_min", area->y_min},
                            {"x_max", area->x_max},
                            {"y_max", area->y_max}};
    } else {
        out["work_area"] = nullptr;
    }
    std::vector<double> xs, ys;
    std::vector<std::uint64_t> ticks;
    std::vector<int> pens;
    std::vector<std::size_t> layers;
    layers.reserve(vertices.size());
    xs.reserve(vertices.size());
    ys.reserve(vertices.size());
    ticks.reserve(vertices.size());
    pens.reserve(vertices.size());
    for (const Vertex& v : vertices) {
        xs.push_back(rounded(v.x, 4));
        ys.push_back(rounded(v.y, 4));
        ticks.push_back(v.tick);
        pens.push_back(v.pen ? 1 : 0);
        layers.push_back(v.layer);
    }
    out["path"] = {{"x", xs}, {"y", ys}, {"tick", ticks}, {"pen", pens}, {"layer", layers}};
    std::vector<double> t, v;
    for (std::size_t b = 0; b < bins; ++b) {
        t.push_back(
            rounded(plan.duration * (static_cast<double>(b) + 0.5) / static_cast<double>(bins), 4));
        v.push_back(rounded(bin_speed[b], 3));
    }
    out["speed"] = {{"t", t}, {"v", v}};
    std::vector<std::uint64_t> pauses;
    for (const PlanPause& p : plan.pauses) pauses.push_back(p.tick);
    out["pauses"] = pauses;
    return out;
}

}  // namespace pathstream::host::serve
