#include "preview.hpp"

#include <algorithm>
#include <cmath>
#include <set>

#include "pathstream/host/isometric.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/placement.hpp"

namespace pathstream::host::serve {
namespace {

struct Vertex {
    double x = 0, y = 0;
    double z = 0;  ///< the 3-D view's z; 0 in 2-D
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

// The same in 3-D: |(b - a) x (p - a)| / |b - a|. Apart from off_chord so that a plotter's
// preview stays what it was to the bit.
double off_chord_3d(const Vertex& a, const Vertex& b, const Vertex& p) {
    const double dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
    const double ex = p.x - a.x, ey = p.y - a.y, ez = p.z - a.z;
    const double length = std::hypot(dx, dy, dz);
    if (length < 1e-12) return std::hypot(ex, ey, ez);
    return std::hypot(dy * ez - dz * ey, dz * ex - dx * ez, dx * ey - dy * ex) / length;
}

// Keeps the vertices that the tolerance needs: a run from the last kept vertex grows while
// every point in it stays within `tolerance` of the chord and the pen stays the same; the
// runs are bounded so that a long gentle curve costs a fixed amount of work per vertex.
class Simplifier {
public:
    Simplifier(double tolerance, bool three_d) : tolerance_(tolerance), three_d_(three_d) {}

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
        if (three_d_) {
            const Vertex& b = run_.back();
            if (std::hypot(v.x - a.x, v.y - a.y, v.z - a.z) <
                std::hypot(b.x - a.x, b.y - a.y, b.z - a.z))
                return false;
            return std::all_of(run_.begin(), run_.end(), [&](const Vertex& p) {
                return off_chord_3d(a, v, p) <= tolerance_;
            });
        }
        if (std::hypot(v.x - a.x, v.y - a.y) < std::hypot(run_.back().x - a.x, run_.back().y - a.y))
            return false;
        return std::all_of(run_.begin(), run_.end(),
                           [&](const Vertex& p) { return off_chord(a, v, p) <= tolerance_; });
    }

    double tolerance_;
    bool three_d_;
    std::vector<Vertex> kept_, run_;
};

// v to `digits` decimals, as the nearest double to that decimal (it prints as written).
double rounded(double v, int digits) {
    const double scale = std::pow(10.0, digits);
    return std::round(v * scale) / scale;
}

}  // namespace

struct PreviewRecorder::State {
    State(const Path& p, const MachineProfile& m, const PreviewOptions& o)
        : path(p),
          machine(m),
          options(o),
          xyz(xyz_axes(m)),
          simplifier(o.tolerance_mm, xyz.has_value()) {
        fine.assign(std::max<std::size_t>(2, 2 * o.speed_samples), 0.0);
    }
    const Path& path;
    const MachineProfile& machine;
    PreviewOptions options;
    std::optional<XyzAxes> xyz;  ///< a router's x, y, z: the page shows the isometric view
    Simplifier simplifier;
    std::set<std::size_t> drawn_subpaths;
    std::uint64_t tick = 0;
    std::size_t spans = 0;
    /// Known total (preview_json of a whole plan): each span goes to its final bin at once.
    std::uint64_t known_total = 0;
    std::vector<double> exact;
    /// Unknown total: fine bins of `width` ticks, merged in pairs when the job outgrows them.
    std::vector<double> fine;
    double width = 256;

    void add_speed(std::uint64_t start, double speed) {
        if (known_total > 0) {
            const std::size_t bins = exact.size();
            const std::size_t bin =
                std::min(bins - 1, static_cast<std::size_t>(static_cast<double>(start) /
                                                            static_cast<double>(known_total) *
                                                            static_cast<double>(bins)));
            exact[bin] = std::max(exact[bin], speed);
            return;
        }
        while (static_cast<double>(start) / width >= static_cast<double>(fine.size())) {
            const std::size_t half = fine.size() / 2;
            for (std::size_t i = 0; i < half; ++i) fine[i] = std::max(fine[2 * i], fine[2 * i + 1]);
            std::fill(fine.begin() + static_cast<std::ptrdiff_t>(half), fine.end(), 0.0);
            width *= 2;
        }
        const auto k = static_cast<std::size_t>(static_cast<double>(start) / width);
        fine[k] = std::max(fine[k], speed);
    }
};

PreviewRecorder::PreviewRecorder(const Path& path, const MachineProfile& machine,
                                 const PreviewOptions& options)
    : state_(std::make_unique<State>(path, machine, options)) {}

PreviewRecorder::~PreviewRecorder() = default;

void PreviewRecorder::span(const CoreSpan& s) {
    State& st = *state_;
    const double mm = st.machine.mm_per_lsb;
    // The planner's spans are Hermite (P0, P1, T0, T1): P0 where it starts, P1 where it ends.
    const std::size_t layer =
        s.subpath < st.path.subpaths.size() ? st.path.subpaths[s.subpath].layer : 0;
    if (st.xyz) {
        const XyzAxes& a = *st.xyz;
        const auto at = [&](int end) {
            return Vertex{s.control.at(a.x)[end] * mm,
                          s.control.at(a.y)[end] * mm,
                          s.control.at(a.z)[end] * mm,
                          0,
                          false,
                          layer};
        };
        if (st.spans == 0) st.simplifier.add(at(0));
        Vertex v = at(1);
        const Vertex from = at(0);
        st.add_speed(st.tick, std::hypot(v.x - from.x, v.y - from.y, v.z - from.z) *
                                  st.machine.tick_hz / s.ticks);
        st.tick += s.ticks;
        ++st.spans;
        if (s.pen_down) st.drawn_subpaths.insert(s.subpath);
        v.tick = st.tick;
        v.pen = s.pen_down;
        st.simplifier.add(v);
        return;
    }
    const std::size_t ax = st.machine.axes.size();
    if (st.spans == 0)
        st.simplifier.add(
            {s.control.at(0)[0] * mm, ax > 1 ? s.control.at(1)[0] * mm : 0.0, 0, 0, false, layer});
    const double dx = (s.control.at(0)[1] - s.control.at(0)[0]) * mm;
    const double dy = ax > 1 ? (s.control.at(1)[1] - s.control.at(1)[0]) * mm : 0.0;
    st.add_speed(st.tick, std::hypot(dx, dy) * st.machine.tick_hz / s.ticks);
    st.tick += s.ticks;
    ++st.spans;
    if (s.pen_down) st.drawn_subpaths.insert(s.subpath);
    st.simplifier.add({s.control.at(0)[1] * mm, ax > 1 ? s.control.at(1)[1] * mm : 0.0, 0, st.tick,
                       s.pen_down, layer});
}

nlohmann::ordered_json PreviewRecorder::finish(double duration_s, std::uint64_t total_ticks,
                                               std::size_t pen_changes, double drawn_length_mm,
                                               double travel_length_mm) {
    State& st = *state_;
    const std::vector<Vertex> vertices = st.simplifier.finish();
    const std::size_t bins = std::max<std::size_t>(1, std::min(st.options.speed_samples, st.spans));
    std::vector<double> bin_speed(bins, 0.0);
    if (st.known_total > 0) {
        bin_speed = st.exact;
    } else {
        const double total = std::max<double>(1, static_cast<double>(total_ticks));
        for (std::size_t k = 0; k < st.fine.size(); ++k) {
            const double start = static_cast<double>(k) * st.width;
            if (start >= total) break;
            const std::size_t bin = std::min(
                bins - 1, static_cast<std::size_t>(start / total * static_cast<double>(bins)));
            bin_speed[bin] = std::max(bin_speed[bin], st.fine[k]);
        }
    }

    nlohmann::ordered_json summary;
    summary["duration_s"] = duration_s;
    summary["ticks"] = total_ticks;
    summary["tick_hz"] = st.machine.tick_hz;
    summary["spans"] = st.spans;
    summary["subpaths"] = st.drawn_subpaths.size();
    summary["pen_changes"] = pen_changes;
    summary["pauses"] = pauses_.size();
    summary["layers"] = layers_json(st.path);
    summary["drawn_length_mm"] = drawn_length_mm;
    summary["travel_length_mm"] = travel_length_mm;
    summary["vertices"] = vertices.size();

    nlohmann::ordered_json out;
    out["summary"] = summary;
    if (const auto area = work_area(st.machine)) {
        out["work_area"] = {{"x_min", area->x_min},
                            {"y_min", area->y_min},
                            {"x_max", area->x_max},
                            {"y_max", area->y_max}};
    } else {
        out["work_area"] = nullptr;
    }
    if (st.xyz) {
        // The page draws x, y, z in the isometric view; `axes` are the machine's indexes of
        // them (rest_mm is in the machine's order), `box` its x, y, z travel when all have one.
        const XyzAxes& a = *st.xyz;
        const AxisLimits &x = st.machine.axes[a.x], &y = st.machine.axes[a.y],
                         &z = st.machine.axes[a.z];
        nlohmann::ordered_json view;
        view["projection"] = "isometric";
        view["axes"] = {a.x, a.y, a.z};
        if (x.has_travel && y.has_travel && z.has_travel) {
            view["box"] = {{"x_min", x.travel_min}, {"y_min", y.travel_min},
                           {"z_min", z.travel_min}, {"x_max", x.travel_max},
                           {"y_max", y.travel_max}, {"z_max", z.travel_max}};
        } else {
            view["box"] = nullptr;
        }
        out["view"] = view;
    }
    std::vector<double> xs, ys, zs;
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
        if (st.xyz) zs.push_back(rounded(v.z, 4));
        ticks.push_back(v.tick);
        pens.push_back(v.pen ? 1 : 0);
        layers.push_back(v.layer);
    }
    out["path"] = {{"x", xs}, {"y", ys}, {"tick", ticks}, {"pen", pens}, {"layer", layers}};
    if (st.xyz) out["path"]["z"] = zs;
    std::vector<double> t, v;
    for (std::size_t b = 0; b < bins; ++b) {
        t.push_back(
            rounded(duration_s * (static_cast<double>(b) + 0.5) / static_cast<double>(bins), 4));
        v.push_back(rounded(bin_speed[b], 3));
    }
    out["speed"] = {{"t", t}, {"v", v}};
    out["pauses"] = pauses_;
    return out;
}

nlohmann::ordered_json preview_json(const Plan& plan, const Path& path,
                                    const MachineProfile& machine, const PreviewOptions& options) {
    PreviewRecorder recorder(path, machine, options);
    recorder.state_->known_total = std::max<std::uint64_t>(1, plan.total_ticks);
    recorder.state_->exact.assign(
        std::max<std::size_t>(1, std::min(options.speed_samples, plan.spans.size())), 0.0);
    for (const CoreSpan& s : plan.spans) recorder.span(s);
    for (const PlanPause& p : plan.pauses) recorder.pause(p.tick);
    return recorder.finish(plan.duration, plan.total_ticks, plan.pen.size(), plan.path_length,
                           plan.travel_length);
}

}  // namespace pathstream::host::serve
