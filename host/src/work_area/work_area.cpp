#include "pathstream/host/work_area.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "pathstream/device/motion_limits.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {
namespace {

std::string mm(double v) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(3);
    s << v;
    return s.str();
}

std::string point_text(const BezierSegment& s, double t, std::size_t axes) {
    const PathPoint p = bezier_point(s, t);
    std::string text = "(";
    for (std::size_t a = 0; a < axes; ++a) text += (a ? ", " : "") + mm(p[a]);
    return text + ") mm";
}

SourceLocation location_of(const Path& path, std::size_t subpath) {
    return subpath < path.subpaths.size() ? path.subpaths[subpath].location : SourceLocation{};
}

// The move a segment comes from where the reader kept it (G-code), else its subpath's start.
SourceLocation location_of(const Path& path, const BezierSegment& s) {
    if (s.subpath < path.subpaths.size()) {
        const Subpath& sp = path.subpaths[s.subpath];
        if (sp.segment_lines.size() == chain_segments(sp) && s.segment < sp.segment_lines.size()) {
            return {sp.segment_lines[s.segment], 1};
        }
    }
    return location_of(path, s.subpath);
}

}  // namespace

void check_segment_work_area(const BezierSegment& s, const Path& path,
                             const MachineProfile& profile, const std::string& file) {
    if (!s.pen_down) return;
    const std::size_t axes = profile.axes.size();
    for (std::size_t a = 0; a < axes && a < s.p[0].size(); ++a) {
        const AxisLimits& l = profile.axes[a];
        if (!l.has_travel) continue;
        for (double t : extreme_parameters(s, a)) {
            const double v = bezier_point(s, t)[a];
            if (v >= l.travel_min - 1e-6 && v <= l.travel_max + 1e-6) continue;
            throw InputError(file, location_of(path, s),
                             "subpath " + std::to_string(s.subpath + 1) +
                                 " leaves the work area: it reaches " + l.name + " = " + mm(v) +
                                 " mm at " + point_text(s, t, axes) + "; " + l.name +
                                 " travel is " + mm(l.travel_min) + " .. " + mm(l.travel_max) +
                                 " mm (" + profile.source + ")");
        }
    }
}

void check_work_area(const std::vector<BezierSegment>& segments, const Path& path,
                     const MachineProfile& profile, const std::string& file) {
    for (const BezierSegment& s : segments) check_segment_work_area(s, path, profile, file);
}

void check_span_travel(const CoreSpan& s, std::size_t index, const Path& path,
                       const MachineProfile& profile, const std::string& file) {
    const bool any = std::any_of(profile.axes.begin(), profile.axes.end(),
                                 [](const AxisLimits& l) { return l.has_travel; });
    if (!any) return;
    const DeviceLimitsLsb lsb = device_limits(profile);
    for (std::size_t a = 0; a < profile.axes.size() && a < s.cubic.size(); ++a) {
        if (!profile.axes[a].has_travel) continue;
        device::AxisLimits l;
        l.min_position = lsb.min_position[a];
        l.max_position = lsb.max_position[a];
        if (device::check_axis_travel(s.cubic[a], s.timing, l) == Status::kOk) continue;
        const AxisLimits& axis = profile.axes[a];
        const double from = s.control[a][0] * profile.mm_per_lsb;
        throw InputError(
            file, location_of(path, s.subpath),
            "planned span " + std::to_string(index + 1) + " (subpath " +
                std::to_string(s.subpath + 1) + (s.pen_down ? "" : ", pen-up travel") + ", from " +
                axis.name + " = " + mm(from) + " mm) could leave the " + axis.name + " travel " +
                mm(axis.travel_min) + " .. " + mm(axis.travel_max) +
                " mm, and the device would refuse it: the path runs within the chord tolerance (" +
                mm(profile.chord_tolerance) + " mm) of the edge; move it inside by that much");
    }
}

void check_plan_travel(const Plan& plan, const Path& path, const MachineProfile& profile,
                       const std::string& file) {
    for (std::size_t i = 0; i < plan.spans.size(); ++i)
        check_span_travel(plan.spans[i], i, path, profile, file);
}

}  // namespace pathstream::host
