// SpanQueue: the fixed-capacity single-producer/single-consumer ring between the task that
// prepares spans and the tick interrupt. Single-threaded contract checks, then a two-thread
// stress run (order, no loss, no duplicate) for the sanitizer builds to watch.
#include <atomic>
#include <catch2/catch.hpp>
#include <cstdint>
#include <random>
#include <thread>
#include <vector>

#include "core/property_settings.hpp"
#include "pathstream/span_queue.hpp"

using pathstream::SpanQueue;

namespace {

/// A slot payload large enough that a torn or stale read is visible: every word is derived
/// from the sequence number.
struct Item {
    std::uint64_t sequence = 0;
    std::uint64_t check[3] = {0, 0, 0};
    void fill(std::uint64_t s) {
        sequence = s;
        for (int i = 0; i < 3; ++i)
            check[i] = s * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(i);
    }
    bool consistent() const {
        for (int i = 0; i < 3; ++i) {
            if (check[i] != sequence * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(i))
                return false;
        }
        return true;
    }
};

}  // namespace

TEST_CASE("An empty queue has no front and all slots free", "[queue]") {
    SpanQueue<int, 4> q;
    CHECK(q.front() == nullptr);
    CHECK(q.size() == 0);
    CHECK(q.free_slots() == 4);
    CHECK(q.capacity() == 4);
    CHECK(SpanQueue<int, 64>::capacity() == 64);
    // A claim alone publishes nothing.
    int* slot = q.claim();
    REQUIRE(slot != nullptr);
    *slot = 5;
    CHECK(q.front() == nullptr);
    CHECK(q.size() == 0);
    // Claiming again without publishing hands out the same slot.
    CHECK(q.claim() == slot);
    q.publish();
    REQUIRE(q.front() != nullptr);
    CHECK(*q.front() == 5);
    CHECK(q.size() == 1);
    CHECK(q.free_slots() == 3);
    q.release();
    CHECK(q.front() == nullptr);
    CHECK(q.size() == 0);
}

TEST_CASE("A full queue refuses claims until the consumer releases", "[queue]") {
    SpanQueue<int, 8> q;
    for (int i = 0; i < 8; ++i) {
        int* slot = q.claim();
        REQUIRE(slot != nullptr);
        *slot = 100 + i;
        q.publish();
        CHECK(q.size() == static_cast<std::uint32_t>(i + 1));
        CHECK(q.free_slots() == static_cast<std::uint32_t>(7 - i));
    }
    CHECK(q.claim() == nullptr);
    CHECK(q.claim() == nullptr);
    CHECK(q.size() == 8);
    CHECK(q.free_slots() == 0);
    // The consumer still sees the oldest, and the refused claims changed nothing.
    REQUIRE(q.front() != nullptr);
    CHECK(*q.front() == 100);
    // Front without release is idempotent.
    CHECK(q.front() == q.front());
    q.release();
    CHECK(q.size() == 7);
    int* slot = q.claim();
    REQUIRE(slot != nullptr);
    *slot = 200;
    q.publish();
    CHECK(q.claim() == nullptr);
    // FIFO: 101..107, then 200.
    for (int i = 1; i < 8; ++i) {
        REQUIRE(q.front() != nullptr);
        CHECK(*q.front() == 100 + i);
        q.release();
    }
    REQUIRE(q.front() != nullptr);
    CHECK(*q.front() == 200);
    q.release();
    CHECK(q.front() == nullptr);
    CHECK(q.free_slots() == 8);
}

TEST_CASE("Queue keeps FIFO order through many wrap-arounds at every fill level", "[queue]") {
    const auto seed = pathstream::test::property_seed();
    INFO("seed " << seed);
    std::mt19937_64 rng(seed);
    SpanQueue<Item, 16> q;
    std::uint64_t produced = 0, consumed = 0;
    std::vector<Item*> seen_slots;
    // Random bursts of pushes and pops: ~40,000 operations, so the free-running indices wrap
    // the ring thousands of times.
    for (int round = 0; round < 4000; ++round) {
        const auto pushes = static_cast<int>(rng() % 20);
        for (int i = 0; i < pushes; ++i) {
            Item* slot = q.claim();
            if (produced - consumed == 16) {
                REQUIRE(slot == nullptr);
                break;
            }
            REQUIRE(slot != nullptr);
            slot->fill(produced++);
            q.publish();
        }
        REQUIRE(q.size() == produced - consumed);
        REQUIRE(q.free_slots() == 16 - (produced - consumed));
        const auto pops = static_cast<int>(rng() % 20);
        for (int i = 0; i < pops; ++i) {
            Item* front = q.front();
            if (produced == consumed) {
                REQUIRE(front == nullptr);
                break;
            }
            REQUIRE(front != nullptr);
            REQUIRE(front->sequence == consumed);
            REQUIRE(front->consistent());
            ++consumed;
            q.release();
        }
        REQUIRE(q.size() == produced - consumed);
    }
    REQUIRE(produced > 16 * 1000);  // many wraps
    // Slots are reused in ring order: 16 consecutive claims cover 16 distinct slots.
    while (q.front() != nullptr) q.release();
    for (int i = 0; i < 16; ++i) {
        Item* slot = q.claim();
        REQUIRE(slot != nullptr);
        for (Item* s : seen_slots) REQUIRE(s != slot);
        seen_slots.push_back(slot);
        q.publish();
    }
    REQUIRE(q.claim() == nullptr);
}

TEST_CASE("Two threads: one producer, one consumer, nothing lost, duplicated or reordered",
          "[queue][threads]") {
    constexpr std::uint64_t kItems = 1000000;
    SpanQueue<Item, 64> q;
    std::atomic<bool> failed{false};
    std::uint64_t producer_full = 0;

    std::thread producer([&] {
        for (std::uint64_t i = 0; i < kItems && !failed.load(std::memory_order_relaxed);) {
            Item* slot = q.claim();
            if (slot == nullptr) {
                ++producer_full;
                std::this_thread::yield();
                continue;
            }
            slot->fill(i);
            q.publish();
            // The producer's view of free room never exceeds the capacity.
            if (q.free_slots() > 64) failed.store(true);
            ++i;
        }
    });

    std::uint64_t expected = 0, empty_polls = 0, bad_sequence = 0, torn = 0;
    std::uint64_t first_bad = 0;
    while (expected < kItems && !failed.load(std::memory_order_relaxed)) {
        Item* front = q.front();
        if (front == nullptr) {
            ++empty_polls;
            std::this_thread::yield();
            continue;
        }
        if (front->sequence != expected) {
            if (bad_sequence++ == 0) first_bad = front->sequence;
        }
        if (!front->consistent()) ++torn;
        if (q.size() > 64) failed.store(true);
        q.release();
        ++expected;
        if (bad_sequence > 100) failed.store(true);
    }
    producer.join();
    INFO("first out-of-order sequence " << first_bad << "; producer saw full " << producer_full
                                        << " times, consumer saw empty " << empty_polls
                                        << " times");
    CHECK_FALSE(failed.load());
    CHECK(bad_sequence == 0);
    CHECK(torn == 0);
    CHECK(expected == kItems);
    CHECK(q.front() == nullptr);
    CHECK(q.size() == 0);
}
