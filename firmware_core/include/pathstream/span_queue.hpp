// Fixed-capacity single-producer/single-consumer queue with inline storage.
#pragma once

#include <atomic>
#include <cstdint>

namespace pathstream {

/// Ring of Capacity slots of T, no allocation. One producer (a task) claims a slot, fills it
/// in place and publishes it; one consumer (e.g. the tick interrupt) reads the oldest slot in
/// place and releases it. Only 32-bit atomic loads and stores are used, which are lock-free
/// on every Cortex-M (no read-modify-write, so ARMv6-M needs no libatomic).
/// Capacity must be a power of two below 2^31.
template <typename T, std::uint32_t Capacity>
class SpanQueue {
    static_assert(Capacity >= 2 && (Capacity & (Capacity - 1)) == 0, "power of two");
    static_assert(Capacity < (std::uint32_t{1} << 31), "indices are free-running uint32");

public:
    /// Producer: the next free slot to fill, or nullptr when full. The slot is invisible to
    /// the consumer until publish(). Calling claim() twice without publish() returns the same
    /// slot. O(1). Producer context only.
    T* claim() {
        const std::uint32_t head = head_.load(std::memory_order_relaxed);
        const std::uint32_t tail = tail_.load(std::memory_order_acquire);
        if (head - tail == Capacity) return nullptr;
        return &slots_[head & (Capacity - 1)];
    }

    /// Producer: makes the slot returned by the last claim() visible. O(1). Producer only.
    void publish() {
        head_.store(head_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
    }

    /// Consumer: the oldest published slot, or nullptr when empty. O(1). Consumer only.
    T* front() {
        const std::uint32_t tail = tail_.load(std::memory_order_relaxed);
        if (head_.load(std::memory_order_acquire) == tail) return nullptr;
        return &slots_[tail & (Capacity - 1)];
    }

    /// Consumer: frees the slot returned by front(). Precondition: front() was non-null.
    void release() {
        tail_.store(tail_.load(std::memory_order_relaxed) + 1, std::memory_order_release);
    }

    /// Published slots not yet released. Either side; exact from the consumer's view, a lower
    /// bound of free room from the producer's.
    std::uint32_t size() const {
        return head_.load(std::memory_order_acquire) - tail_.load(std::memory_order_acquire);
    }
    std::uint32_t free_slots() const { return Capacity - size(); }
    static constexpr std::uint32_t capacity() { return Capacity; }

private:
    T slots_[Capacity];
    std::atomic<std::uint32_t> head_{0};  // written by the producer only
    std::atomic<std::uint32_t> tail_{0};  // written by the consumer only
};

}  // namespace pathstream
