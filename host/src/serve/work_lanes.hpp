// The workers behind the HTTP server: one small pool per Lane, each with a bounded queue, so
// that planning never occupies the worker a stop needs and a flood of requests is refused
// rather than queued without end.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "http_types.hpp"

namespace pathstream::host::serve {

/// A fixed set of threads per lane and a queue of at most `queue_limit` tasks per lane.
/// Threads start in the constructor and are joined by shutdown() (or the destructor).
class WorkLanes {
public:
    /// `workers[i]` threads for Lane i (stop, command, work).
    WorkLanes(std::vector<std::size_t> workers, std::size_t queue_limit);
    ~WorkLanes();
    WorkLanes(const WorkLanes&) = delete;
    WorkLanes& operator=(const WorkLanes&) = delete;

    /// Queues `task` on `lane`. False (and `task` dropped) when that lane's queue is full or
    /// the lanes shut down. Any thread.
    bool submit(Lane lane, std::function<void()> task);

    /// Drops the queued tasks, waits for the running ones to return and joins the threads.
    /// Any thread but a worker's; idempotent.
    void shutdown();

private:
    struct Pool {
        std::deque<std::function<void()>> queue;
        std::vector<std::thread> threads;
    };
    void work(Pool& pool);

    std::mutex mutex_;
    std::condition_variable ready_;
    std::vector<Pool> pools_;
    std::size_t queue_limit_;
    bool closed_ = false;
};

}  // namespace pathstream::host::serve
