// The planner's thread and its end of the span queue (docs/cli.md, "Planning while streaming").
#include "pathstream/host/planning_thread.hpp"

#include <chrono>
#include <stdexcept>

namespace pathstream::host {

// The sink plan_stream feeds on the planning thread: the tap first, then the queue.
class PlanningThread::Forward : public PlanSink {
public:
    explicit Forward(PlanningThread& owner) : owner_(owner) {}
    void span(const CoreSpan& s) override {
        if (owner_.hooks_.tap != nullptr) owner_.hooks_.tap->span(s);
        owner_.push(s);
    }
    void pen(const PenEvent& e) override {
        if (owner_.hooks_.tap != nullptr) owner_.hooks_.tap->pen(e);
    }
    void pause(const PlanPause& p) override {
        if (owner_.hooks_.tap != nullptr) owner_.hooks_.tap->pause(p);
    }

private:
    PlanningThread& owner_;
};

PlanningThread::PlanningThread(SegmentSource& source, const MachineProfile& profile,
                               const PlanOptions& options, Hooks hooks)
    : source_(source),
      profile_(profile),
      options_(options),
      hooks_(std::move(hooks)),
      ring_(std::make_unique<SpscRing<QueuedSpan, kCapacity>>()) {
    thread_ = std::thread([this] { run(); });
}

PlanningThread::~PlanningThread() {
    cancel();
    if (thread_.joinable()) thread_.join();
}

void PlanningThread::run() {
    const auto t0 = std::chrono::steady_clock::now();
    try {
        Forward sink(*this);
        const PlanTotals totals =
            plan_stream(source_, profile_, options_, sink, hooks_.check, nullptr, [this](double f) {
                if (cancel_.load(std::memory_order_relaxed)) throw Cancelled{};
                fraction_.store(f, std::memory_order_relaxed);
            });
        if (hooks_.finish) hooks_.finish(totals);
        totals_ = totals;
        fraction_.store(1, std::memory_order_relaxed);
    } catch (const Cancelled&) {
        error_ = std::make_exception_ptr(std::runtime_error("planning cancelled"));
    } catch (...) {
        error_ = std::current_exception();
    }
    seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    done_.store(true, std::memory_order_release);
}

// On the planning thread: one span into the ring, waiting while it is full.
void PlanningThread::push(const CoreSpan& s) {
    if (s.control.size() > kMaxAxes) throw std::invalid_argument("1 to 8 axes");
    QueuedSpan q;
    q.ticks = s.ticks;
    q.subpath = static_cast<std::uint32_t>(s.subpath);
    q.axes = static_cast<std::uint8_t>(s.control.size());
    q.pen_down = s.pen_down;
    q.machine = s.machine;
    q.pause_after = s.pause_after;
    for (std::size_t a = 0; a < s.control.size(); ++a) {
        for (unsigned k = 0; k < 4; ++k) q.control[a][k] = s.control[a][k];
    }
    while (!ring_->try_push(q)) {
        if (cancel_.load(std::memory_order_relaxed)) throw Cancelled{};
        std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
}

SpanSupply::Take PlanningThread::take(CoreSpan& out) {
    // done_ first: a span pushed before the end is in the ring when done_ reads true.
    const bool done = done_.load(std::memory_order_acquire);
    if (done && error_) std::rethrow_exception(error_);
    QueuedSpan q;
    if (!ring_->try_pop(q)) return done ? Take::kEnd : Take::kWait;
    out.basis = Basis::kHermite;
    out.ticks = q.ticks;
    out.subpath = q.subpath;
    out.pen_down = q.pen_down;
    out.machine = q.machine;
    out.pause_after = q.pause_after;
    out.control.resize(q.axes);
    for (std::size_t a = 0; a < q.axes; ++a) {
        for (unsigned k = 0; k < 4; ++k) out.control[a][k] = q.control[a][k];
    }
    out.cubic.clear();
    out.timing = {};
    return Take::kSpan;
}

std::optional<std::uint64_t> PlanningThread::total_ticks() const {
    if (!finished() || !totals_) return std::nullopt;
    return totals_->total_ticks;
}

std::optional<PlanTotals> PlanningThread::totals() const {
    if (!finished()) return std::nullopt;
    return totals_;
}

double PlanningThread::planning_seconds() const {
    return finished() ? seconds_ : 0;
}

void PlanningThread::drain(const std::function<bool()>& keep_waiting) {
    QueuedSpan q;
    auto last_ask = std::chrono::steady_clock::now();
    while (!finished()) {
        while (ring_->try_pop(q)) {
        }
        const auto now = std::chrono::steady_clock::now();
        if (now - last_ask >= std::chrono::milliseconds(20)) {
            last_ask = now;
            if (keep_waiting && !keep_waiting()) cancel();
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
}

}  // namespace pathstream::host
