// The planner on a thread of its own, feeding a streaming client through a bounded queue of
// spans: streaming begins after the first window is planned, and memory does not grow with the
// job (docs/cli.md, "Planning while streaming").
#pragma once

#include <atomic>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <optional>
#include <thread>

#include "pathstream/host/planner.hpp"
#include "pathstream/host/span_supply.hpp"
#include "pathstream/host/spsc_ring.hpp"
#include "pathstream/machine/machine.hpp"
#include "pathstream/span.hpp"

namespace pathstream::host {

/// One span on its way from the planning thread to the streaming thread: a CoreSpan's Hermite
/// control points in a record of fixed size (no allocation inside the queue).
struct QueuedSpan {
    std::uint32_t ticks = 0;
    std::uint32_t subpath = 0;
    std::uint8_t axes = 0;
    bool pen_down = false;
    bool pause_after = false;
    std::uint8_t machine = 0;  ///< CoreSpan::machine
    std::int32_t control[kMaxAxes][4] = {};
};

/// Plans a job with plan_stream on its own thread and hands the spans, once they passed the
/// planner's per-tick check, to the streaming thread through a SpscRing of kCapacity spans.
/// The planning thread waits (sleeping 0.2 ms at a time) while the ring is full, so it runs
/// at most kCapacity spans ahead of what the streamer took.
///
/// Shared state, each written by one side only: the ring (see SpscRing); `done_`, stored last
/// by the planning thread (release) after `totals_`, `error_` and `seconds_`, which the
/// streaming thread reads only after loading `done_` true (acquire); `fraction_` (planning
/// thread) and `cancel_` (streaming thread), read whole as atomics.
class PlanningThread : public SpanSupply {
public:
    static constexpr std::size_t kCapacity = 4096;

    /// What runs on the planning thread around the planner. `tap` sees every span, pen event
    /// and pause before the queue does (checks, a journal's plan file); `finish` runs after
    /// the last span with the planner's totals (a final check, closing a file). Either may
    /// throw: the exception ends planning and reaches the streamer like the planner's own.
    struct Hooks {
        PlanSink* tap = nullptr;
        std::function<void(const PlanTotals&)> finish;
        /// plan_stream's own per-tick check, given to it (its result is set before `finish`
        /// runs): the whole PlanCheck, the deviation included, without a second check.
        StreamCheck* check = nullptr;
    };

    /// Starts planning `source` for `profile` with `options` on a new thread. `source`,
    /// `profile` and the hooks' objects must outlive this object; they are used from the
    /// planning thread only until finished() (or the destructor). Allocates the ring (about
    /// 600 KB) once.
    PlanningThread(SegmentSource& source, const MachineProfile& profile, const PlanOptions& options,
                   Hooks hooks);
    /// Cancels planning if it still runs and joins the thread.
    ~PlanningThread() override;
    PlanningThread(const PlanningThread&) = delete;
    PlanningThread& operator=(const PlanningThread&) = delete;

    /// Streaming thread: SpanSupply::take. A span is converted into `out` (its control
    /// vector reused). Rethrows planning's exception at once, even with spans still queued:
    /// what follows an error is not streamed.
    Take take(CoreSpan& out) override;
    /// Streaming thread: the job's ticks once planning finished without error.
    std::optional<std::uint64_t> total_ticks() const override;

    /// Either thread: planning ended, with its last span queued, with an error or cancelled.
    bool finished() const { return done_.load(std::memory_order_acquire); }
    /// Streaming thread, after finished(): the planner's totals (nullopt after an error).
    std::optional<PlanTotals> totals() const;
    /// Streaming thread, after finished(): seconds from the start to the end of planning.
    double planning_seconds() const;
    /// Either thread: plan_stream's progress, 0..1.
    double fraction() const { return fraction_.load(std::memory_order_relaxed); }
    /// Spans queued now (a snapshot).
    std::size_t queued() const { return ring_->size(); }

    /// Streaming thread: ends planning as soon as the planning thread next hands over a span
    /// or reports progress (its hooks then see no more). Spans already queued stay takeable.
    void cancel() { cancel_.store(true, std::memory_order_relaxed); }
    /// Streaming thread: waits for the planning thread to end, taking and dropping every span
    /// it queues meanwhile (so that it can finish); `keep_waiting` is asked every 20 ms and
    /// a false cancels planning.
    void drain(const std::function<bool()>& keep_waiting);

private:
    struct Cancelled {};
    void run();
    void push(const CoreSpan& span);

    class Forward;
    SegmentSource& source_;
    const MachineProfile& profile_;
    PlanOptions options_;
    Hooks hooks_;
    std::unique_ptr<SpscRing<QueuedSpan, kCapacity>> ring_;
    std::atomic<bool> done_{false};
    std::atomic<bool> cancel_{false};
    std::atomic<double> fraction_{0};
    std::optional<PlanTotals> totals_;
    std::exception_ptr error_;
    double seconds_ = 0;
    std::thread thread_;
};

}  // namespace pathstream::host
