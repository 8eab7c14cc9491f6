// From the host's runtime-sized spans to the core's compile-time axis count: the one place
// that turns a CoreSpan into a pathstream::Span<Axes> and a runtime axis count into a template.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <utility>

#include "pathstream/machine/core_span.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host {

/// The core's wire form of `in` with `tag`; the pen flag becomes kOutputPenDown.
/// `in` must have at least Axes axes.
template <unsigned Axes>
Span<Axes> to_core_span(const CoreSpan& in, std::uint32_t tag) {
    Span<Axes> s;
    s.basis = in.basis;
    s.ticks = in.ticks;
    s.tag = tag;
    s.outputs = span_outputs(in);
    for (unsigned a = 0; a < Axes; ++a) {
        for (unsigned i = 0; i < 4; ++i) s.control[a][i] = in.control[a][i];
    }
    return s;
}

/// The host's form of a span the core made (a device move: stop, re-entry), for `subpath`, pen
/// down or up, with the machine functions `machine`; its timing and cubics are left for the
/// caller to fill.
template <unsigned Axes>
CoreSpan from_core_span(const Span<Axes>& in, std::size_t subpath, bool pen_down,
                        std::uint8_t machine = 0) {
    CoreSpan c;
    c.basis = in.basis;
    c.ticks = in.ticks;
    c.subpath = subpath;
    c.pen_down = pen_down;
    c.machine = machine;
    c.control.assign(Axes, {});
    for (unsigned a = 0; a < Axes; ++a) {
        for (unsigned i = 0; i < 4; ++i) c.control[a][i] = in.control[a][i];
    }
    return c;
}

/// Calls `f(std::integral_constant<unsigned, A>{})` with A = `axes` (1..8) and returns its
/// result. Throws std::invalid_argument for any other axis count.
template <typename F>
decltype(auto) with_axes(std::size_t axes, F&& f) {
    switch (axes) {
        case 1:
            return f(std::integral_constant<unsigned, 1>{});
        case 2:
            return f(std::integral_constant<unsigned, 2>{});
        case 3:
            return f(std::integral_constant<unsigned, 3>{});
        case 4:
            return f(std::integral_constant<unsigned, 4>{});
        case 5:
            return f(std::integral_constant<unsigned, 5>{});
        case 6:
            return f(std::integral_constant<unsigned, 6>{});
        case 7:
            return f(std::integral_constant<unsigned, 7>{});
        case 8:
            return f(std::integral_constant<unsigned, 8>{});
    }
    throw std::invalid_argument("1 to 8 axes, not " + std::to_string(axes));
}

}  // namespace pathstream::host
