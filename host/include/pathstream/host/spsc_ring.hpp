// A fixed-capacity queue between exactly two threads: one pushes, the other pops. The planner
// thread hands spans to the streaming thread through it (docs/cli.md, "Planning while
// streaming").
#pragma once

#include <array>
#include <atomic>
#include <cstddef>

namespace pathstream::host {

/// Single producer, single consumer, `Capacity` slots (a power of two), no allocation after
/// construction, never blocks. Each index is written by one side only: `tail_` by the producer
/// (after it filled the slot: a release store), `head_` by the consumer (after it copied the
/// slot out). A slot is read by the consumer only below the tail it acquired, and written by the
/// producer only above the head it acquired, so no slot is ever accessed by both at once.
template <typename T, std::size_t Capacity>
class SpscRing {
    static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "capacity: a power of two");

public:
    /// Producer thread only. Copies `item` in; false (nothing changed) when the ring is full.
    /// O(1), wait-free.
    bool try_push(const T& item) {
        const std::size_t tail = tail_.load(std::memory_order_relaxed);
        if (tail - head_.load(std::memory_order_acquire) == Capacity) return false;
        slots_[tail & (Capacity - 1)] = item;
        tail_.store(tail + 1, std::memory_order_release);
        return true;
    }

    /// Consumer thread only. Copies the oldest item into `out` and frees its slot; false
    /// (`out` untouched) when the ring is empty. O(1), wait-free.
    bool try_pop(T& out) {
        const std::size_t head = head_.load(std::memory_order_relaxed);
        if (head == tail_.load(std::memory_order_acquire)) return false;
        out = slots_[head & (Capacity - 1)];
        head_.store(head + 1, std::memory_order_release);
        return true;
    }

    /// Items pushed and not yet popped, as seen from either thread (a snapshot: the other
    /// side may change it at once). The head is read first: the tail read after it is never
    /// behind it. O(1).
    std::size_t size() const {
        const std::size_t head = head_.load(std::memory_order_acquire);
        return tail_.load(std::memory_order_acquire) - head;
    }

    static constexpr std::size_t capacity() { return Capacity; }

private:
    std::array<T, Capacity> slots_{};
    alignas(64) std::atomic<std::size_t> head_{0};  // next slot to pop; the consumer's
    alignas(64) std::atomic<std::size_t> tail_{0};  // next slot to push; the producer's
};

}  // namespace pathstream::host
