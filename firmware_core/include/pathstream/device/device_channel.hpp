// Everything the device's two contexts share, and nothing else: the span queue, the mailbox
// the task side posts requests to, and the status board the tick side publishes to. Every
// shared word is a 32-bit atomic used with loads and stores only (ARMv6-M has no atomic
// read-modify-write); each has exactly one writing context, named below.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>

#include "pathstream/device/device_state.hpp"
#include "pathstream/device/motion_limits.hpp"
#include "pathstream/setpoint_stream.hpp"
#include "pathstream/units.hpp"

namespace pathstream::device {

/// A value of `T` (32-bit words only) published by one writer and read whole by any reader:
/// one sequence lock. The writer makes the sequence odd, stores the words, makes it even; a
/// reader copies the words between two loads of an even, unchanged sequence, else retries.
/// publish() stores only the first `HotWords` words when told the others did not change since
/// the last publish(): what a tick changes on every tick sits first in `T`, so the tick pays
/// for the rest only on the ticks that change it. The writer never waits. On a single-core
/// MCU the writer is the tick interrupt and a reader retries at most once per tick that
/// interrupts its copy.
///
/// Ordering: one release fence after the odd sequence and one acquire fence after the word
/// loads, the words themselves relaxed (on Cortex-M: one DMB per publish instead of one per
/// word). ThreadSanitizer does not model standalone fences (GCC refuses them under
/// -fsanitize=thread), so a ThreadSanitizer build orders every word itself instead (release
/// stores, acquire loads): the same guarantee, checked by the tool.
template <typename T, unsigned HotWords>
class StatusBoard {
    static_assert(sizeof(T) % sizeof(std::uint32_t) == 0, "32-bit words only");
    static constexpr unsigned kWords = sizeof(T) / sizeof(std::uint32_t);
    static_assert(HotWords <= kWords, "hot words are a prefix of T");
#if defined(__SANITIZE_THREAD__)
    static constexpr bool kWordOrdered = true;
#else
    static constexpr bool kWordOrdered = false;
#endif
    static constexpr std::memory_order kWordStore =
        kWordOrdered ? std::memory_order_release : std::memory_order_relaxed;
    static constexpr std::memory_order kWordLoad =
        kWordOrdered ? std::memory_order_acquire : std::memory_order_relaxed;

public:
    /// Writer only (one context). `all`: store every word; otherwise only the first HotWords
    /// (the caller guarantees the rest equal the last publish()). Cost: two sequence stores,
    /// one fence, HotWords (or all) word loads and stores.
    void publish(const T& value, bool all) {
        // Word-aligned (T is made of 32-bit words): whole-word loads, also on ARMv6-M.
        const auto* bytes = static_cast<const unsigned char*>(
            __builtin_assume_aligned(static_cast<const void*>(&value), alignof(std::uint32_t)));
        const std::uint32_t sequence = sequence_.load(std::memory_order_relaxed);
        sequence_.store(sequence + 1, std::memory_order_relaxed);
        // A reader that sees any word of this publish() also sees the odd sequence stored
        // before it, and retries.
        if constexpr (!kWordOrdered) std::atomic_thread_fence(std::memory_order_release);
        if (all) {
            store_words<kWords>(bytes);
        } else {
            store_words<HotWords>(bytes);  // a constant count: unrolled, no loop per word
        }
        sequence_.store(sequence + 2, std::memory_order_release);
    }

    /// Any context that cannot preempt the writer (it would spin while the writer it
    /// interrupted is inside publish()). Returns a copy of one publish() whole. Cost: kWords
    /// loads per try.
    T read() const {
        std::uint32_t words[kWords];
        for (;;) {
            const std::uint32_t before = sequence_.load(std::memory_order_acquire);
            if ((before & 1u) != 0) continue;
            for (unsigned i = 0; i < kWords; ++i) words[i] = words_[i].load(kWordLoad);
            // Keeps the second sequence load after every word load.
            if constexpr (!kWordOrdered) std::atomic_thread_fence(std::memory_order_acquire);
            if (sequence_.load(std::memory_order_relaxed) == before) break;
        }
        T value;
        __builtin_memcpy(&value, words, sizeof words);
        return value;
    }

private:
    template <unsigned Count>
    void store_words(const unsigned char* bytes) {
#pragma GCC unroll 32
        for (unsigned i = 0; i < Count; ++i) {
            std::uint32_t word;
            __builtin_memcpy(&word, bytes + i * sizeof word, sizeof word);
            words_[i].store(word, kWordStore);
        }
    }

    std::atomic<std::uint32_t> sequence_{0};  // written by the writer only; odd while writing
    std::atomic<std::uint32_t> words_[kWords] = {};
};

/// Command-word values that only the task side posts (never bus values): the operator's pen
/// (lowered or raised at rest while idle), and a start that keeps that pen (the device's own
/// jog); a plain start raises it.
inline constexpr std::uint32_t kMailboxValueMask = 0x7Fu;
inline constexpr std::uint32_t kMailboxKeepPen = 0x80u;
inline constexpr std::uint32_t kMailboxPenUp = 0x40u;
inline constexpr std::uint32_t kMailboxPenDown = 0x41u;

/// Requests to the tick. Who writes each field and when is part of its contract.
template <unsigned Axes>
struct DeviceMailbox {
    /// Command word: (request number << 8) | Command value, or a mailbox-only value
    /// (kMailboxPenUp, kMailboxPenDown), possibly with kMailboxKeepPen on a start. Written by
    /// the task side (DeviceReceiver::command, start_keeping_pen, set_pen) in one store; the
    /// tick takes each new word once. A second request before that tick replaces the first.
    std::atomic<std::uint32_t> command{0};
    /// Fault request: 0 or a FaultCode. Written by any context (raise_fault, first code kept)
    /// and cleared by the tick when a reset leaves the fault.
    std::atomic<std::uint32_t> fault{0};
    /// E-stop input level (0 released, 1 active). Written by any context (the input's edge
    /// interrupt or poll); read by the tick.
    std::atomic<std::uint32_t> estop{0};
    /// set_position request: `position` is written by the task, then `position_request`
    /// (release); the tick reads `position` after seeing a new number (acquire) and reports
    /// it taken in DeviceStatus::position_applied. The task never writes `position` while a
    /// request is pending, so the array itself needs no atomics.
    Lsb position[Axes] = {};
    std::atomic<std::uint32_t> position_request{0};
    /// Configuration. Written by the task only while the device is idle with nothing queued
    /// (DeviceReceiver::configure); read by the tick only while it runs, holds or stops, which
    /// it reaches through a start command posted after the write (the command's release and
    /// the tick's acquire order the two), so the limits are never read while written.
    MotionLimits<Axes> limits{};
};

/// The three things the task side and the tick side share. Init context builds it; then
/// `queue` has one producer (the task side: DeviceReceiver) and one consumer (the tick side:
/// DeviceExecutor), `mailbox` is written as documented per field, and `board` is written by
/// the tick only.
template <unsigned Axes, std::uint32_t Capacity>
struct DeviceChannel {
    /// Idle at `start` (LSB per axis). Init context.
    explicit DeviceChannel(const Lsb (&start)[Axes]) : queue(start) {
        DeviceStatus<Axes> s;
        for (unsigned a = 0; a < Axes; ++a) s.origin[a] = s.position[a] = start[a];
        board.publish(s, true);
    }

    /// Spans with their stamps (epoch, job, end tangent). Producer: task; consumer: tick.
    SetpointStream<Axes, Capacity> queue;
    DeviceMailbox<Axes> mailbox;
    /// The tick's status, published once per tick.
    StatusBoard<DeviceStatus<Axes>, DeviceStatus<Axes>::kHotWords> board;
    static_assert(offsetof(DeviceStatus<Axes>, tick_check) ==
                      (DeviceStatus<Axes>::kHotWords - 1) * sizeof(std::uint32_t),
                  "the hot words end at tick_check");
};

}  // namespace pathstream::device
