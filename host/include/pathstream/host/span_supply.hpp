// Where a streaming client gets the spans it sends: a plan held in memory, or the planner as it
// makes them (PlanningThread), so that streaming can begin before planning ends.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>

#include "pathstream/host/core_spans.hpp"
#include "pathstream/host/plan.hpp"

namespace pathstream::host {

/// The spans of one job in order, handed out one at a time. Called from the streaming thread
/// only.
class SpanSupply {
public:
    enum class Take {
        kSpan,  ///< `out` holds the next span
        kWait,  ///< none yet: planning goes on; ask again later
        kEnd,   ///< the job has no more spans
    };
    virtual ~SpanSupply() = default;
    /// The next span into `out`. Never blocks. Rethrows the error planning failed with
    /// (PlanError, InputError, ...) as soon as it is known, spans not yet taken or not.
    virtual Take take(CoreSpan& out) = 0;
    /// The job's ticks, once known (planning finished); nullopt before.
    virtual std::optional<std::uint64_t> total_ticks() const = 0;
};

/// A plan held in memory as a supply (not copied: `plan` must outlive it). O(1) per span,
/// plus the copy of the span into `out`.
class PlanSupply : public SpanSupply {
public:
    explicit PlanSupply(const Plan& plan) : plan_(plan) {}
    Take take(CoreSpan& out) override {
        if (next_ >= plan_.spans.size()) return Take::kEnd;
        out = plan_.spans[next_++];
        return Take::kSpan;
    }
    std::optional<std::uint64_t> total_ticks() const override { return plan_.total_ticks; }

private:
    const Plan& plan_;
    std::size_t next_ = 0;
};

}  // namespace pathstream::host
