#include "pathstream/host/core_spans.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "pathstream/machine/input_error.hpp"
#include "pathstream/status.hpp"
#include "pathstream/tick_cubic.hpp"

namespace pathstream::host {
namespace {

using LsbPoint = std::vector<std::int64_t>;

LsbPoint quantise(PointRef p, double mm_per_lsb) {
    LsbPoint q;
    for (double mm : p) q.push_back(std::llround(mm / mm_per_lsb));
    return q;
}

LsbPoint reflect(const LsbPoint& end, const LsbPoint& next) {  // phantom point 2 end - next
    LsbPoint r;
    for (std::size_t a = 0; a < end.size(); ++a) r.push_back(2 * end[a] - next[a]);
    return r;
}

/// Four-point windows of a uniform B-spline or Catmull-Rom subpath: open ends get phantom
/// points so the curve starts at the first point and ends at the last.
std::vector<std::array<const LsbPoint*, 4>> windows(const std::vector<LsbPoint>& pts, bool closed,
                                                    std::vector<LsbPoint>& storage) {
    std::vector<const LsbPoint*> ext;
    const std::size_t m = pts.size();
    storage.clear();
    storage.reserve(2);
    std::vector<std::array<const LsbPoint*, 4>> out;
    if (closed) {
        for (std::size_t i = 0; i < m; ++i) {
            out.push_back({&pts[(i + m - 1) % m], &pts[i], &pts[(i + 1) % m], &pts[(i + 2) % m]});
        }
        return out;
    }
    storage.push_back(reflect(pts[0], pts[1]));
    storage.push_back(reflect(pts[m - 1], pts[m - 2]));
    ext.push_back(&storage[0]);
    for (const auto& p : pts) ext.push_back(&p);
    ext.push_back(&storage[1]);
    for (std::size_t i = 0; i + 3 < ext.size(); ++i)
        out.push_back({ext[i], ext[i + 1], ext[i + 2], ext[i + 3]});
    return out;
}

/// The core's view of one axis of a span: validated timing and cubic.
Status to_core(const CoreSpan& span, std::size_t axis, SpanTiming& timing, TickCubic& cubic) {
    const auto& a = span.control[axis];
    const std::int32_t c[4] = {a[0], a[1], a[2], a[3]};
    Status s = make_span_timing(span.basis, span.ticks, timing);
    if (s == Status::kOk) s = make_tick_cubic(span.basis, c, timing, cubic);
    return s;
}

/// Builds the spans of one subpath, checking each against the core's ranges.
class SubpathBuilder {
public:
    SubpathBuilder(const std::string& file, std::size_t axes, std::uint32_t ticks,
                   std::size_t subpath, SourceLocation at)
        : file_(file), axes_(axes), ticks_(ticks), subpath_(subpath), at_(at) {}

    void add(Basis basis, const LsbPoint& p0, const LsbPoint& p1, const LsbPoint& p2,
             const LsbPoint& p3, bool pen_down = true) {
        const LsbPoint* p[4] = {&p0, &p1, &p2, &p3};
        CoreSpan span;
        span.basis = basis;
        span.ticks = ticks_;
        span.subpath = subpath_;
        span.pen_down = pen_down;
        for (std::size_t a = 0; a < axes_; ++a) {
            std::array<std::int32_t, 4> c{};
            for (std::size_t i = 0; i < 4; ++i) {
                const std::int64_t v = (*p[i])[a];
                const bool tangent = basis == Basis::kHermite && i >= 2;
                const std::int64_t limit = tangent ? kMaxTangentLsb : kMaxPositionLsb;
                if (v < -limit || v > limit) {
                    std::ostringstream m;
                    m << "subpath " << subpath_ << ": axis " << a
                      << (tangent ? " tangent " : " value ") << v
                      << " LSB is outside the core's range +/-" << limit
                      << " LSB (use a coarser --lsb or move the drawing)";
                    throw InputError(file_, at_, m.str());
                }
                c[i] = static_cast<std::int32_t>(v);
            }
            span.control.push_back(c);
            TickCubic cubic;
            if (const Status s = to_core(span, a, span.timing, cubic); s != Status::kOk) {
                std::ostringstream m;
                m << "subpath " << subpath_ << ", span " << spans_.size() << ", axis " << a
                  << ": the core rejects it: " << status_name(s);
                throw InputError(file_, at_, m.str());
            }
            span.cubic.push_back(cubic);
        }
        spans_.push_back(std::move(span));
    }

    /// A straight Hermite segment: both tangents equal the chord, so p(u) = a + u (b - a).
    void line(const LsbPoint& a, const LsbPoint& b, bool pen_down = true) {
        LsbPoint chord;
        for (std::size_t ax = 0; ax < axes_; ++ax) chord.push_back(b[ax] - a[ax]);
        add(Basis::kHermite, a, b, chord, chord, pen_down);
    }

    std::vector<CoreSpan>& spans() { return spans_; }

private:
    const std::string& file_;
    std::size_t axes_;
    std::uint32_t ticks_;
    std::size_t subpath_;
    SourceLocation at_;
    std::vector<CoreSpan> spans_;
};

std::vector<CoreSpan> subpath_spans(const Path& path, std::size_t s, const std::string& file,
                                    double mm_per_lsb, std::uint32_t ticks) {
    const Subpath& sp = path.subpaths[s];
    std::vector<LsbPoint> pts;
    for (const auto& p : sp.points) pts.push_back(quantise(p, mm_per_lsb));
    const std::size_t m = pts.size();
    SubpathBuilder b(file, path.axes, ticks, s, sp.location);
    switch (sp.basis) {
        case PathBasis::kBSpline:
        case PathBasis::kCatmullRom: {
            const Basis basis =
                sp.basis == PathBasis::kBSpline ? Basis::kUniformBSpline : Basis::kCatmullRom;
            std::vector<LsbPoint> storage;
            for (const auto& w : windows(pts, sp.closed, storage))
                b.add(basis, *w[0], *w[1], *w[2], *w[3]);
            break;
        }
        case PathBasis::kBezier: {
            const std::size_t count = sp.closed ? m / 3 : (m - 1) / 3;
            for (std::size_t i = 0; i < count; ++i) {
                b.add(Basis::kBezier, pts[3 * i], pts[3 * i + 1], pts[3 * i + 2],
                      pts[(3 * i + 3) % m]);
            }
            break;
        }
        case PathBasis::kPolyline: {
            const std::size_t count = sp.closed ? m : m - 1;
            for (std::size_t i = 0; i < count; ++i) b.line(pts[i], pts[(i + 1) % m]);
            break;
        }
    }
    return std::move(b.spans());
}

}  // namespace

std::vector<CoreSpan> uniform_core_spans(const Path& path, const std::string& file,
                                         double mm_per_lsb, std::uint32_t ticks_per_span) {
    std::vector<CoreSpan> out;
    for (std::size_t s = 0; s < path.subpaths.size(); ++s) {
        std::vector<CoreSpan> spans = subpath_spans(path, s, file, mm_per_lsb, ticks_per_span);
        if (!out.empty()) {  // straight pen-up travel between the exact end and start points
            LsbPoint from, to;
            for (std::size_t a = 0; a < path.axes; ++a) {
                from.push_back(core_value_at(out.back(), a, out.back().ticks));
                to.push_back(core_value_at(spans.front(), a, 0));
            }
            SubpathBuilder travel(file, path.axes, ticks_per_span, s, path.subpaths[s].location);
            travel.line(from, to, false);
            out.push_back(std::move(travel.spans().front()));
        }
        for (auto& span : spans) out.push_back(std::move(span));
    }
    return out;
}

}  // namespace pathstream::host
