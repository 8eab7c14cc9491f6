#include "work_lanes.hpp"

namespace pathstream::host::serve {

WorkLanes::WorkLanes(std::vector<std::size_t> workers, std::size_t queue_limit)
    : pools_(workers.size()), queue_limit_(queue_limit) {
    for (std::size_t p = 0; p < pools_.size(); ++p) {
        for (std::size_t t = 0; t < workers[p]; ++t)
            pools_[p].threads.emplace_back([this, p] { work(pools_[p]); });
    }
}

WorkLanes::~WorkLanes() {
    shutdown();
}

bool WorkLanes::submit(Lane lane, std::function<void()> task) {
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        Pool& pool = pools_.at(static_cast<std::size_t>(lane));
        if (closed_ || pool.queue.size() >= queue_limit_) return false;
        pool.queue.push_back(std::move(task));
    }
    ready_.notify_all();
    return true;
}

void WorkLanes::shutdown() {
    {
        const std::lock_guard<std::mutex> lock(mutex_);
        if (closed_) return;
        closed_ = true;
        for (Pool& pool : pools_) pool.queue.clear();
    }
    ready_.notify_all();
    for (Pool& pool : pools_) {
        for (std::thread& t : pool.threads) t.join();
    }
}

// One worker: the lane's next task until shutdown.
void WorkLanes::work(Pool& pool) {
    for (;;) {
        std::function<void()> task;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            ready_.wait(lock, [&] { return closed_ || !pool.queue.empty(); });
            if (closed_) return;
            task = std::move(pool.queue.front());
            pool.queue.pop_front();
        }
        task();
    }
}

}  // namespace pathstream::host::serve
