#include "pathstream/host/core_playback.hpp"

#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

#include "pathstream/machine/core_span_conversion.hpp"
#include "pathstream/setpoint_stream.hpp"

namespace pathstream::host {
namespace {

template <unsigned Axes>
std::uint64_t play(const std::vector<CoreSpan>& spans,
                   const std::function<void(const PlayedTick&)>& on_tick) {
    Lsb start[Axes];
    for (unsigned a = 0; a < Axes; ++a) start[a] = core_value_at(spans.front(), a, 0);
    // The host may allocate: one stream object (inline storage, tens of kB) on the heap.
    const auto stream = std::make_unique<SetpointStream<Axes, 64>>(start);
    std::size_t next_to_push = 0;
    std::uint32_t tick_in_span = 0;
    std::uint64_t calls = 0;
    Lsb out[Axes];
    for (;;) {
        while (next_to_push < spans.size() && stream->free_slots() > 0) {
            const Span<Axes> s =
                to_core_span<Axes>(spans[next_to_push], static_cast<std::uint32_t>(next_to_push));
            if (const Status st = stream->push(s); st != Status::kOk) {
                throw std::runtime_error("the core refused span " + std::to_string(next_to_push) +
                                         ": " + status_name(st));
            }
            ++next_to_push;
        }
        const std::size_t current = stream->spans_completed();
        if (stream->tick(out) == TickState::kIdle) break;
        for (unsigned a = 0; a < Axes; ++a) {
            if (out[a] != core_value_at(spans[current], a, tick_in_span)) {
                std::ostringstream m;
                m << "forward differencing and Horner disagree at tick " << calls
                  << " (a core bug)";
                throw std::logic_error(m.str());
            }
        }
        on_tick(PlayedTick{calls++, current, tick_in_span, out,
                           (stream->outputs() & kOutputPenDown) != 0});
        tick_in_span = stream->spans_completed() != current ? 0 : tick_in_span + 1;
    }
    // The end point, held once the queue has run dry: the state stepped once past the last
    // tick, which must be the span's exact tick-n value.
    for (unsigned a = 0; a < Axes; ++a) {
        if (out[a] != core_value_at(spans.back(), a, spans.back().ticks)) {
            throw std::logic_error("the held end point differs from Horner's tick n (a core bug)");
        }
    }
    on_tick(PlayedTick{calls++, spans.size() - 1, spans.back().ticks, out, spans.back().pen_down});
    return calls;
}

}  // namespace

std::uint64_t play_through_core(const std::vector<CoreSpan>& spans, std::size_t axes,
                                const std::function<void(const PlayedTick&)>& on_tick) {
    if (spans.empty()) return 0;
    return with_axes(axes, [&](auto n) { return play<decltype(n)::value>(spans, on_tick); });
}

}  // namespace pathstream::host
