// Size probe: every template of the core that a firmware with one SetpointStream<A, 16>
// instantiates, emitted out of line (explicit instantiation), so that the object's .text is
// the core's template code for that configuration. Compiled once per A with -DPROBE_AXES=A.
// Core .text (docs/cortex-m.md) = library objects' .text + this object's .text.
#include "pathstream/setpoint_stream.hpp"

#ifndef PROBE_AXES
#error "define PROBE_AXES"
#endif

template class pathstream::SetpointStream<PROBE_AXES, 16>;
template pathstream::Status pathstream::prepare_span<PROBE_AXES>(
    const pathstream::Span<PROBE_AXES>&, pathstream::PreparedSpan<PROBE_AXES>&);
