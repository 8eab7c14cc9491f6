// One job at a time on a second thread while the caller prepares the next: plan_stream checks
// window N tick by tick there while it plans window N + 1 (docs/planner.md §8).
#pragma once

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <utility>

namespace pathstream::host {

/// Runs `job(work)` on each piece of work the caller submits, one at a time, and hands the
/// work back with the job's verdict when the caller collects it. With Mode::kThread the job
/// runs on a thread of its own (started by the constructor); with Mode::kCaller there is no
/// thread and the job runs inside step() or collect() on the caller's thread (one core, and
/// the seeded interleaving tests, which call step() where the thread would run).
///
/// Shared state, each part written by one side only and all of it under one mutex:
/// `submitted_`, `stop_` and the work while no job is pending are the caller's; `finished_`,
/// `verdict_` and `error_` are the job side's. The job reads the work only between the submit
/// that counted it and the finish it publishes; the caller touches the work again only after
/// collect() saw that finish. The job runs without the lock.
///
/// Costs: one thread (kThread), no allocation per job beyond what swapping `Work` does.
/// Work must be default-constructible and swappable.
template <class Work>
class HandoffWorker {
public:
    enum class Mode { kThread, kCaller };
    /// The job: true when the work passed. May throw; the exception reaches collect().
    using Job = std::function<bool(const Work&)>;

    /// Init. Starts the thread in kThread mode. `job` must stay callable until destruction.
    HandoffWorker(Job job, Mode mode) : job_(std::move(job)), mode_(mode) {
        if (mode_ == Mode::kThread) thread_ = std::thread([this] { loop(); });
    }
    /// Lets the submitted job (running or not yet started) run to its end, then joins the
    /// thread; an uncollected verdict is dropped.
    ~HandoffWorker() {
        if (!thread_.joinable()) return;
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            stop_ = true;
        }
        wake_job_.notify_one();
        thread_.join();
    }
    HandoffWorker(const HandoffWorker&) = delete;
    HandoffWorker& operator=(const HandoffWorker&) = delete;

    /// Caller: hands `work` to the job (swapped in: `work` gets what collect() last swapped
    /// out, as it was; the caller clears it if it must). Precondition: !busy().
    void submit(Work& work) {
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            using std::swap;
            swap(work_, work);
            ++submitted_;
        }
        busy_ = true;
        wake_job_.notify_one();
    }

    /// Caller: a piece of work was submitted and not yet collected.
    bool busy() const { return busy_; }

    /// Caller: the job on the submitted work has finished (collect() will not wait).
    bool ready() const {
        const std::lock_guard<std::mutex> lock(mutex_);
        return submitted_ > collected_ && finished_ == submitted_;
    }

    /// Job side in kCaller mode: runs the job on the submitted work if it has not run yet.
    /// Returns whether it ran. Never used in kThread mode (the thread does this).
    bool step() {
        if (mode_ != Mode::kCaller) return false;
        std::uint64_t target;
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            if (finished_ == submitted_) return false;
            target = submitted_;
        }
        run_job(target);
        return true;
    }

    /// Caller: waits for the job on the submitted work (kCaller: runs it here if step() has
    /// not), swaps the work back into `work` and returns the verdict, or rethrows what the job
    /// threw. Precondition: busy().
    bool collect(Work& work) {
        if (mode_ == Mode::kCaller) (void)step();
        std::unique_lock<std::mutex> lock(mutex_);
        job_done_.wait(lock, [this] { return finished_ == submitted_; });
        collected_ = submitted_;
        using std::swap;
        swap(work_, work);
        const std::exception_ptr error = error_;
        const bool verdict = verdict_;
        lock.unlock();
        busy_ = false;
        if (error) std::rethrow_exception(error);
        return verdict;
    }

    /// Caller: the count of jobs run (and collected or not) so far.
    std::uint64_t jobs_finished() const {
        const std::lock_guard<std::mutex> lock(mutex_);
        return finished_;
    }

private:
    // The thread: waits for submitted work (or the stop), runs the job, publishes the finish.
    void loop() {
        for (;;) {
            std::uint64_t target;
            {
                std::unique_lock<std::mutex> lock(mutex_);
                wake_job_.wait(lock, [this] { return stop_ || finished_ != submitted_; });
                if (finished_ == submitted_) return;  // stopped with nothing pending
                target = submitted_;
            }
            run_job(target);
        }
    }

    // The job on the work of submission `target`, its verdict or exception published with it.
    void run_job(std::uint64_t target) {
        bool verdict = false;
        std::exception_ptr error;
        try {
            verdict = job_(work_);
        } catch (...) {
            error = std::current_exception();
        }
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            verdict_ = verdict;
            error_ = error;
            finished_ = target;
        }
        job_done_.notify_one();
    }

    Job job_;
    Mode mode_;
    mutable std::mutex mutex_;
    std::condition_variable wake_job_, job_done_;
    Work work_{};
    std::uint64_t submitted_ = 0, collected_ = 0;  // the caller's
    bool stop_ = false;                            // the caller's
    std::uint64_t finished_ = 0;                   // the job side's
    bool verdict_ = false;                         // the job side's
    std::exception_ptr error_;                     // the job side's
    bool busy_ = false;                            // the caller's alone (never read by the job)
    std::thread thread_;
};

}  // namespace pathstream::host
