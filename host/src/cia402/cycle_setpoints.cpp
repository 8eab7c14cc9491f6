#include "cycle_setpoints.hpp"

#include <stdexcept>
#include <string>

#include "pathstream/machine/core_span_conversion.hpp"
#include "pathstream/setpoint_stream.hpp"

namespace pathstream::host::cia402 {
namespace {

template <unsigned Axes>
class Decimated final : public CycleSetpoints {
public:
    Decimated(const std::vector<CoreSpan>& spans, std::uint32_t c) : spans_(spans), c_(c) {
        Lsb start[Axes];
        for (unsigned a = 0; a < Axes; ++a) start[a] = core_value_at(spans.front(), a, 0);
        stream_ = std::make_unique<SetpointStream<Axes, 64>>(start);
    }

    bool next(std::int32_t* out) override {
        if (done_) return false;
        // The first call plays tick 0, every later one C ticks; tick() returns a tick's setpoint
        // and steps, so the last of them is the setpoint of tick C x calls.
        const std::uint32_t steps = calls_ == 0 ? 1 : c_;
        Lsb v[Axes];
        for (std::uint32_t i = 0; i < steps; ++i) {
            refill();
            if (stream_->tick(v) == TickState::kIdle) {
                done_ = true;  // v holds the end point (the last span's tick n)
                break;
            }
        }
        ++calls_;
        for (unsigned a = 0; a < Axes; ++a) out[a] = v[a];
        return true;
    }

    std::uint64_t ticks() const override { return stream_->ticks_executed(); }

private:
    void refill() {
        while (next_span_ < spans_.size() && stream_->free_slots() > 0) {
            const Span<Axes> s =
                to_core_span<Axes>(spans_[next_span_], static_cast<std::uint32_t>(next_span_ + 1));
            if (const Status st = stream_->push(s); st != Status::kOk) {
                throw std::runtime_error("the core refused span " + std::to_string(next_span_) +
                                         ": " + status_name(st));
            }
            ++next_span_;
        }
    }

    const std::vector<CoreSpan>& spans_;
    std::uint32_t c_;
    std::unique_ptr<SetpointStream<Axes, 64>> stream_;  // tens of kB inline: on the heap
    std::size_t next_span_ = 0;
    std::uint64_t calls_ = 0;
    bool done_ = false;
};

}  // namespace

std::unique_ptr<CycleSetpoints> make_cycle_setpoints(const std::vector<CoreSpan>& spans,
                                                     std::size_t axes,
                                                     std::uint32_t ticks_per_cycle) {
    if (spans.empty()) throw std::invalid_argument("the plan has no spans");
    if (ticks_per_cycle == 0) throw std::invalid_argument("ticks per cycle must be >= 1");
    return with_axes(axes, [&](auto n) -> std::unique_ptr<CycleSetpoints> {
        return std::make_unique<Decimated<decltype(n)::value>>(spans, ticks_per_cycle);
    });
}

}  // namespace pathstream::host::cia402
