// A run's record of bounded size: the report's figures over every tick as it passes, and what
// the plots draw, thinned so that memory does not grow with the run.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "pathstream/host/plot.hpp"

namespace pathstream::host::plot {
namespace {

/// The smallest and largest value of each stretch of `width` ticks (a power of two), at most
/// `capacity` stretches: when a tick falls past them, neighbours merge and the width doubles.
/// Capacity 0 keeps every value (ticks must then come in order, one each).
class Envelope {
public:
    explicit Envelope(std::size_t capacity) : capacity_(capacity) {}

    void add(std::uint64_t tick, double v) {
        if (!have_first_) {
            have_first_ = true;
            first_ = {tick, v};
        }
        if (!have_last_ || tick >= last_.tick) last_ = {tick, v};
        have_last_ = true;
        if (capacity_ == 0) {
            every_.push_back(v);
            return;
        }
        std::uint64_t i = tick / width_;
        while (i >= capacity_) {
            merge();
            i = tick / width_;
        }
        if (i >= slots_.size()) slots_.resize(i + 1);
        Slot& s = slots_[i];
        if (!s.any || v < s.lo.v) s.lo = {tick, v};
        if (!s.any || v > s.hi.v) s.hi = {tick, v};
        s.any = true;
    }

    bool thinned() const { return width_ > 1; }
    void reserve(std::uint64_t ticks) {
        if (capacity_ == 0) every_.reserve(ticks);
    }

    /// Every value kept, as (time, value) in tick order: the first and the last tick, and each
    /// stretch's minimum and maximum. Call once: what they were kept in is released.
    std::vector<Point> take_points(double tick_hz) {
        std::vector<Point> out;
        const auto time = [&](std::uint64_t k) { return static_cast<double>(k) / tick_hz; };
        if (capacity_ == 0) {
            out.reserve(every_.size());
            for (std::size_t k = 0; k < every_.size(); ++k) out.push_back({time(k), every_[k]});
            std::vector<double>().swap(every_);
            return out;
        }
        if (!have_first_) return out;
        std::uint64_t previous = std::numeric_limits<std::uint64_t>::max();
        const auto emit = [&](const Sample& s) {
            if (s.tick == previous) return;
            if (previous != std::numeric_limits<std::uint64_t>::max() && s.tick < previous) return;
            out.push_back({time(s.tick), s.v});
            previous = s.tick;
        };
        emit(first_);
        for (const Slot& s : slots_) {
            if (!s.any) continue;
            if (s.lo.tick <= s.hi.tick) {
                emit(s.lo);
                emit(s.hi);
            } else {
                emit(s.hi);
                emit(s.lo);
            }
        }
        emit(last_);
        return out;
    }

private:
    struct Sample {
        std::uint64_t tick = 0;
        double v = 0;
    };
    struct Slot {
        Sample lo, hi;
        bool any = false;
    };

    void merge() {
        const std::size_t n = (slots_.size() + 1) / 2;
        for (std::size_t i = 0; i < n; ++i) {
            Slot m = slots_[2 * i];
            if (2 * i + 1 < slots_.size()) {
                const Slot& b = slots_[2 * i + 1];
                if (b.any) {
                    if (!m.any || b.lo.v < m.lo.v) m.lo = b.lo;
                    if (!m.any || b.hi.v > m.hi.v) m.hi = b.hi;
                    m.any = true;
                }
            }
            slots_[i] = m;
        }
        slots_.resize(n);
        width_ *= 2;
    }

    std::size_t capacity_;
    std::uint64_t width_ = 1;
    std::vector<Slot> slots_;
    std::vector<double> every_;
    Sample first_, last_;
    bool have_first_ = false, have_last_ = false;
};

/// A path (axes 0 and 1, or x, y, z in 3-D) thinned to points at least `d` apart, the first
/// point of every pen run kept; when more than `capacity` points are kept, `d` doubles and the
/// points kept are thinned again (pen runs too, once they alone are too many). Capacity 0
/// keeps every point.
class Trace {
public:
    Trace(std::size_t capacity, bool three_d) : capacity_(capacity), three_d_(three_d) {}

    void add(double x, double y, double z, bool pen_down) {
        const TracePoint p{x, y, z, pen_down};
        last_seen_ = p;
        last_kept_ = keep(p, points_.empty() ? nullptr : &points_.back(), d_);
        if (last_kept_) points_.push_back(p);
        if (capacity_ > 0 && points_.size() > capacity_) thin();
    }

    bool thinned() const { return d_ > 0 || coarse_; }
    void reserve(std::uint64_t ticks) {
        if (capacity_ == 0) points_.reserve(ticks + 1);
    }

    std::vector<TracePoint> finish() {
        if (!points_.empty() && !last_kept_) points_.push_back(last_seen_);
        return std::move(points_);
    }

private:
    bool keep(const TracePoint& p, const TracePoint* last, double d) const {
        if (last == nullptr || d == 0) return true;
        if (p.pen_down != last->pen_down && !coarse_) return true;
        return distance(p, *last) >= d;
    }

    // In 2-D the plane's distance alone, as it always was: z is 0 there, but the three-argument
    // hypot may round differently, and a plotter's plots must not change by a point.
    double distance(const TracePoint& a, const TracePoint& b) const {
        return three_d_ ? std::hypot(a.x - b.x, a.y - b.y, a.z - b.z)
                        : std::hypot(a.x - b.x, a.y - b.y);
    }

    void thin() {
        // The first tolerance: the points' extent over the capacity.
        if (d_ == 0) {
            TracePoint lo = points_.front(), hi = lo;
            for (const TracePoint& p : points_) {
                if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) continue;
                lo.x = std::min(lo.x, p.x), hi.x = std::max(hi.x, p.x);
                lo.y = std::min(lo.y, p.y), hi.y = std::max(hi.y, p.y);
                lo.z = std::min(lo.z, p.z), hi.z = std::max(hi.z, p.z);
            }
            const double extent = distance(hi, lo);
            d_ = std::isfinite(extent) && extent > 0 ? extent / static_cast<double>(capacity_)
                                                     : 1e-9;
        }
        for (int round = 0; points_.size() > capacity_ / 2 && round < 200; ++round) {
            d_ *= 2;
            std::size_t runs = 0;
            std::size_t kept = 1;
            for (std::size_t i = 1; i < points_.size(); ++i) {
                const bool last = i + 1 == points_.size();
                if (last || keep(points_[i], &points_[kept - 1], d_)) {
                    if (points_[i].pen_down != points_[kept - 1].pen_down) ++runs;
                    points_[kept++] = points_[i];
                }
            }
            points_.resize(kept);
            if (runs > capacity_ / 4) coarse_ = true;
        }
    }

    std::size_t capacity_;
    bool three_d_;
    double d_ = 0;
    bool coarse_ = false;  ///< pen runs are thinned too
    std::vector<TracePoint> points_;
    TracePoint last_seen_;
    bool last_kept_ = true;
};

}  // namespace

struct RunRecorder::State {
    const MachineProfile& profile;
    std::size_t axes;
    double tick_hz;
    double quantum_mm;
    bool has_plant;
    std::size_t capacity;
    unsigned requested_h;
    bool plots;
    std::optional<XyzAxes> xyz;  ///< the 3-D view's axes, when the machine has them

    unsigned h = 1;       ///< the half window once known
    std::uint64_t n = 0;  ///< ticks seen
    double t = 0;         ///< 1 / tick_hz
    /// The last 2 h + 1 executed ticks (ring), and tick 0.
    std::vector<double> ring;
    std::vector<double> first;
    bool h_final = false;
    std::vector<std::uint8_t> early_pen;  ///< pen of the ticks before h is final

    ExecutedFigures f;
    bool pen_before = false;
    std::uint64_t pen_up_from = 0;
    bool in_pen_up = false;
    std::uint64_t pen_gap = 0;  ///< pen-up intervals closer than this merged (0: none)

    RunRecord r;
    std::vector<Envelope> envelopes;  ///< speed, then each axis's acceleration, then positions
    std::vector<Trace> traces;
    std::vector<double> v;  ///< velocity of one tick, per axis
    std::vector<double> a;  ///< acceleration of one tick, per axis

    State(const MachineProfile& p, std::size_t ax, double hz, double q, bool plant, std::size_t cap,
          unsigned hw, bool pl)
        : profile(p),
          axes(ax),
          tick_hz(hz),
          quantum_mm(q),
          has_plant(plant),
          capacity(cap),
          requested_h(hw),
          plots(pl) {
        // The profile's x, y, z, when the series has them (a recorder's axes are the profile's).
        if (const std::optional<XyzAxes> named = xyz_axes(p);
            named && std::max({named->x, named->y, named->z}) < ax)
            xyz = named;
    }

    /// Row `k` (k in the ring's window) of the executed series, axis `axis`.
    double at(std::uint64_t k, std::size_t axis) const {
        if (k == 0) return first[axis];
        const std::size_t w = 2 * h + 1;
        return ring[(k % w) * axes + axis];
    }

    Envelope& speed_envelope() { return envelopes[0]; }
    Envelope& acceleration_envelope(std::size_t axis) { return envelopes[1 + axis]; }

    void velocity_at(std::uint64_t k, std::uint64_t lo, std::uint64_t hi) {
        double sq = 0;
        for (std::size_t ax = 0; ax < axes; ++ax) {
            const double vel = (at(hi, ax) - at(lo, ax)) / (static_cast<double>(hi - lo) * t);
            sq += vel * vel;
            f.peak_velocity[ax] = std::max(f.peak_velocity[ax], std::fabs(vel));
        }
        const double speed = std::sqrt(sq);
        f.peak_speed = std::max(f.peak_speed, speed);
        if (plots) speed_envelope().add(k, speed);
    }

    void acceleration_at(std::uint64_t kc) {
        const double ht = h * t;
        for (std::size_t ax = 0; ax < axes; ++ax) {
            a[ax] = (at(kc + h, ax) - 2 * at(kc, ax) + at(kc - h, ax)) / (ht * ht);
            f.peak_acceleration[ax] = std::max(f.peak_acceleration[ax], std::fabs(a[ax]));
        }
    }

    void emit_acceleration(std::uint64_t k) {
        if (!plots) return;
        for (std::size_t ax = 0; ax < axes; ++ax) acceleration_envelope(ax).add(k, a[ax]);
    }

    /// Tick j has arrived (h final, j >= h): the velocity of tick j - h and, once a full
    /// window is there, the acceleration of tick j - h.
    void arrived(std::uint64_t j) {
        const std::uint64_t k = j - h;
        velocity_at(k, k >= h ? k - h : 0, j);
        if (j >= 2 * h) {
            acceleration_at(k);
            if (k == h) {
                for (std::uint64_t e = 0; e < h; ++e) emit_acceleration(e);  // the edge's copies
            }
            emit_acceleration(k);
        }
    }

    void pen(bool down) {
        const std::uint64_t k = f.ticks;
        f.pen_down_ticks += down ? 1 : 0;
        if (down && !pen_before) ++f.pen_downs;
        if (!down && pen_before) ++f.pen_ups;
        pen_before = down;
        ++f.ticks;
        if (!plots) return;
        if (!down && !in_pen_up) {
            in_pen_up = true;
            pen_up_from = k;
        } else if (down && in_pen_up) {
            close_pen_up(k);
        }
    }

    void close_pen_up(std::uint64_t end) {
        in_pen_up = false;
        auto& list = r.pen_up;
        if (!list.empty() && pen_gap > 0 && pen_up_from - list.back().second <= pen_gap) {
            list.back().second = end;
        } else {
            list.emplace_back(pen_up_from, end);
        }
        if (capacity > 0 && list.size() > capacity) {
            while (list.size() > capacity / 2) {
                pen_gap = pen_gap == 0 ? 1 : 2 * pen_gap;
                std::size_t kept = 0;
                for (std::size_t i = 1; i < list.size(); ++i) {
                    if (list[i].first - list[kept].second <= pen_gap) {
                        list[kept].second = list[i].second;
                    } else {
                        list[++kept] = list[i];
                    }
                }
                list.resize(kept + 1);
            }
        }
    }
};

RunRecorder::RunRecorder(const MachineProfile& profile, std::size_t axes, double tick_hz,
                         double quantum_mm, bool plant, std::size_t capacity, unsigned half_window,
                         bool plots)
    : s_(std::make_unique<State>(profile, axes, tick_hz, quantum_mm, plant, capacity, half_window,
                                 plots)) {
    if (axes == 0) throw std::invalid_argument("RunRecorder: no axes");
    State& s = *s_;
    s.t = 1.0 / tick_hz;
    // The half window as differentiate picks it for a long series.
    TickSeries probe;
    probe.tick_hz = tick_hz;
    probe.quantum_mm = quantum_mm;
    probe.axes = axes;
    s.h = differentiate(probe, profile, half_window).half_window;
    s.f.axes = axes;
    s.f.peak_velocity.assign(axes, 0.0);
    s.f.peak_acceleration.assign(axes, 0.0);
    s.ring.assign((2 * s.h + 1) * axes, 0.0);
    s.v.assign(axes, 0.0);
    s.a.assign(axes, 0.0);
    s.r.tick_hz = tick_hz;
    s.r.axes = axes;
    s.r.has_plant = plant;
    s.r.xyz = s.xyz;
    if (plots) {
        // Speed, accelerations, and with one axis or in 3-D a position against time per series.
        const bool positions = axes == 1 || s.xyz;
        for (std::size_t i = 0; i < 1 + axes + (positions ? 2 : 0); ++i)
            s.envelopes.emplace_back(capacity);
        // A path's points: eight times as many, so that even a dense drawing keeps them
        // closer than a pixel (65,536 points of 32 bytes by default).
        if (axes >= 2) s.traces.assign(plant ? 2 : 1, Trace(8 * capacity, s.xyz.has_value()));
    }
}

RunRecorder::~RunRecorder() = default;

void RunRecorder::reserve(std::uint64_t ticks) {
    for (Envelope& e : s_->envelopes) e.reserve(ticks);
    for (Trace& t : s_->traces) t.reserve(ticks);
}

void RunRecorder::add(const double* executed_mm, const double* plant_mm, bool pen_down) {
    State& s = *s_;
    const std::uint64_t k = s.n;
    const std::size_t w = 2 * s.h + 1;
    // Until 2 h + 1 ticks are there, the window is not known (a short series narrows it):
    // they are kept, and processed once it is.
    if (k == 0) s.first.assign(executed_mm, executed_mm + s.axes);
    std::copy(executed_mm, executed_mm + s.axes, s.ring.begin() + (k % w) * s.axes);
    ++s.n;
    if (!s.h_final) {
        s.early_pen.push_back(pen_down ? 1 : 0);
        if (s.n == w) {
            s.h_final = true;
            for (std::uint64_t j = s.h; j < w; ++j) s.arrived(j);
        }
    } else {
        s.arrived(k);
    }
    s.pen(pen_down);
    if (!s.plots) return;
    // Bounds and the plots' own records.
    for (std::size_t series = 0; series < (s.has_plant ? 2u : 1u); ++series) {
        const double* p = series == 0 ? executed_mm : plant_mm;
        if (s.axes >= 2) {
            // The plane's axes 0 and 1, or in 3-D the axes named x, y and z.
            const double v[3] = {p[s.xyz ? s.xyz->x : 0], p[s.xyz ? s.xyz->y : 1],
                                 s.xyz ? p[s.xyz->z] : 0.0};
            const int kept = s.xyz ? 3 : 2;
            if (std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2])) {
                for (int ax = 0; ax < kept; ++ax) {
                    if (!s.r.bounded[series]) {
                        s.r.lo[series][ax] = s.r.hi[series][ax] = v[ax];
                    } else {
                        s.r.lo[series][ax] = std::min(s.r.lo[series][ax], v[ax]);
                        s.r.hi[series][ax] = std::max(s.r.hi[series][ax], v[ax]);
                    }
                }
                s.r.bounded[series] = true;
            }
            s.traces[series].add(v[0], v[1], v[2], pen_down);
            if (s.xyz) s.envelopes[1 + s.axes + series].add(k, v[2]);
        } else {
            if (!s.r.bounded[series]) {
                s.r.lo[series][0] = s.r.hi[series][0] = p[0];
                s.r.bounded[series] = true;
            } else {
                s.r.lo[series][0] = std::min(s.r.lo[series][0], p[0]);
                s.r.hi[series][0] = std::max(s.r.hi[series][0], p[0]);
            }
            s.envelopes[1 + s.axes + series].add(k, p[0]);
        }
    }
}

RunRecord RunRecorder::finish() {
    State& s = *s_;
    const std::uint64_t n = s.n;
    if (s.h_final) {
        // The last h ticks' velocities (one-sided towards the end), the accelerations' edge.
        for (std::uint64_t k = n - s.h; k < n; ++k) s.velocity_at(k, k - s.h, n - 1);
        for (std::uint64_t k = n - s.h; k < n; ++k) s.emit_acceleration(k);
        s.f.half_window = s.h;
        const double ht = s.h * s.t;
        s.f.acceleration_noise = 2 * s.quantum_mm / (ht * ht);
    } else {
        // A series shorter than a window: differentiate it whole (it is all still here).
        TickSeries whole;
        whole.tick_hz = s.tick_hz;
        whole.axes = s.axes;
        whole.quantum_mm = s.quantum_mm;
        for (std::uint64_t k = 0; k < n; ++k)
            for (std::size_t ax = 0; ax < s.axes; ++ax) whole.position.push_back(s.at(k, ax));
        whole.pen_down = s.early_pen;
        const Derivatives d = differentiate(whole, s.profile, s.requested_h);
        s.f.half_window = d.half_window;
        s.f.acceleration_noise = d.acceleration_noise;
        for (std::uint64_t k = 0; k < n; ++k) {
            for (std::size_t ax = 0; ax < s.axes; ++ax) {
                s.f.peak_velocity[ax] =
                    std::max(s.f.peak_velocity[ax], std::fabs(d.velocity[k * s.axes + ax]));
                s.f.peak_acceleration[ax] =
                    std::max(s.f.peak_acceleration[ax], std::fabs(d.acceleration[k * s.axes + ax]));
                if (s.plots) s.acceleration_envelope(ax).add(k, d.acceleration[k * s.axes + ax]);
            }
            s.f.peak_speed = std::max(s.f.peak_speed, d.speed[k]);
            if (s.plots) s.speed_envelope().add(k, d.speed[k]);
        }
    }
    if (s.plots && s.in_pen_up) s.close_pen_up(n);
    RunRecord r = std::move(s.r);
    r.figures = s.f;
    if (!s.plots) return r;
    r.speed = s.speed_envelope().take_points(s.tick_hz);
    bool thinned = s.pen_gap > 0;
    for (std::size_t ax = 0; ax < s.axes; ++ax) {
        r.acceleration.push_back(s.acceleration_envelope(ax).take_points(s.tick_hz));
        thinned = thinned || s.acceleration_envelope(ax).thinned();
    }
    thinned = thinned || s.speed_envelope().thinned();
    if (s.axes == 1 || s.xyz) {
        for (std::size_t series = 0; series < (s.has_plant ? 2u : 1u); ++series) {
            r.position[series] = s.envelopes[1 + s.axes + series].take_points(s.tick_hz);
            thinned = thinned || s.envelopes[1 + s.axes + series].thinned();
        }
    }
    for (std::size_t series = 0; series < s.traces.size(); ++series) {
        thinned = thinned || s.traces[series].thinned();
        (series == 0 ? r.executed_path : r.plant_path) = s.traces[series].finish();
    }
    r.thinned = thinned;
    return r;
}

RunRecord record_of(const TickSeries& executed, const TickSeries* plant,
                    const MachineProfile& profile, unsigned half_window, std::size_t capacity) {
    const bool with_plant = plant != nullptr && plant->axes == executed.axes;
    RunRecorder recorder(profile, executed.axes, executed.tick_hz, executed.quantum_mm, with_plant,
                         capacity, half_window);
    const std::size_t n = executed.ticks();
    recorder.reserve(n);
    const std::size_t axes = executed.axes;
    for (std::size_t k = 0; k < n; ++k) {
        const double* p = executed.position.data() + k * axes;
        const double* q = with_plant && k < plant->ticks() ? plant->position.data() + k * axes : p;
        recorder.add(p, q, k < executed.pen_down.size() && executed.pen_down[k] != 0);
    }
    RunRecord r = recorder.finish();
    r.executed_name = executed.name;
    if (with_plant) r.plant_name = plant->name;
    // The pen's figures as the report counts them: from pen_down (which may be shorter than
    // the positions; the ticks stay the positions', the plots' time axis).
    plot::ExecutedFigures& f = r.figures;
    const std::size_t ticks = f.ticks;
    f.pen_down_ticks = f.pen_downs = f.pen_ups = 0;
    pen_figures(executed, f);
    f.ticks = ticks;
    return r;
}

}  // namespace pathstream::host::plot
