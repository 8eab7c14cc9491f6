// The queue between the planning thread and the streaming thread: two real threads (run under
// ThreadSanitizer, tag [threads]) and a seeded single-thread interleaving against a model;
// then the planner on its thread through it, against plan_stream on this one.
#include <catch2/catch.hpp>
#include <cstdint>
#include <deque>
#include <random>
#include <thread>
#include <vector>

#include "pathstream/host/planning_thread.hpp"
#include "pathstream/host/spsc_ring.hpp"
#include "pen_plotter_profile.hpp"
#include "plan_digest.hpp"
#include "random_walk_source.hpp"

using namespace pathstream::host;
using pathstream::host::test::Digest;
using pathstream::host::test::DigestSink;
using pathstream::host::test::pen_plotter;
using pathstream::host::test::RandomWalkSource;

namespace {

// An item whose parts must all come from the same push: a torn copy shows.
struct Item {
    std::uint64_t sequence = 0;
    std::uint64_t check = 0;  // ~sequence
};

}  // namespace

TEST_CASE("SpscRing: a producer and a consumer thread pass every item once, in order, whole",
          "[spsc][threads]") {
    constexpr std::uint64_t kItems = 200000;
    SpscRing<Item, 64> ring;  // small: both sides meet full and empty often
    std::thread producer([&] {
        for (std::uint64_t i = 0; i < kItems;) {
            if (ring.try_push({i, ~i})) {
                ++i;
            } else {
                std::this_thread::yield();
            }
        }
    });
    std::uint64_t expected = 0, torn = 0, out_of_order = 0;
    Item item;
    while (expected < kItems) {
        if (!ring.try_pop(item)) {
            std::this_thread::yield();
            continue;
        }
        if (item.check != ~item.sequence) ++torn;
        if (item.sequence != expected) ++out_of_order;
        ++expected;
    }
    producer.join();
    CHECK(torn == 0);
    CHECK(out_of_order == 0);
    CHECK(ring.size() == 0);
    CHECK_FALSE(ring.try_pop(item));
}

TEST_CASE("SpscRing: a seeded interleaving of pushes and pops behaves as a bounded FIFO",
          "[spsc]") {
    for (const std::uint64_t seed : {1u, 2u, 3u, 42u, 1234u}) {
        INFO("seed " << seed);
        std::mt19937_64 rng(seed);
        SpscRing<std::uint64_t, 8> ring;
        std::deque<std::uint64_t> model;
        std::uint64_t next = 0;
        std::size_t fulls = 0, empties = 0;
        for (int step = 0; step < 20000; ++step) {
            // Runs of one side: the ring goes through full and empty many times.
            const bool push = std::bernoulli_distribution(step / 500 % 2 == 0 ? 0.7 : 0.3)(rng);
            if (push) {
                const bool pushed = ring.try_push(next);
                REQUIRE(pushed == (model.size() < 8));
                if (pushed) {
                    model.push_back(next++);
                } else {
                    ++fulls;
                }
            } else {
                std::uint64_t out = ~0ull;
                const bool popped = ring.try_pop(out);
                REQUIRE(popped == !model.empty());
                if (popped) {
                    REQUIRE(out == model.front());
                    model.pop_front();
                } else {
                    REQUIRE(out == ~0ull);  // untouched
                    ++empties;
                }
            }
            REQUIRE(ring.size() == model.size());
        }
        CHECK(fulls > 0);
        CHECK(empties > 0);
    }
}

TEST_CASE(
    "PlanningThread: the spans cross the queue as plan_stream makes them, the totals after the "
    "last",
    "[spsc][planner][threads]") {
    const MachineProfile machine = pen_plotter();
    // Longer than the queue: the planning thread waits on it, and cannot be finished
    // before the consumer took most of the job.
    RandomWalkSource reference_walk(4500, 7);
    DigestSink reference;
    const PlanTotals expected = plan_stream(reference_walk, machine, PlanOptions{}, reference);
    REQUIRE(expected.spans > 2 * PlanningThread::kCapacity);

    RandomWalkSource walk(4500, 7);
    DigestSink tapped;
    PlanningThread planning(walk, machine, PlanOptions{}, {&tapped, {}});
    Digest taken;
    CoreSpan span;
    bool finished_before_half = false;
    for (bool end = false; !end;) {
        switch (planning.take(span)) {
            case SpanSupply::Take::kSpan:
                taken.add(span);
                if (taken.spans == expected.spans / 2) finished_before_half = planning.finished();
                break;
            case SpanSupply::Take::kWait:
                std::this_thread::sleep_for(std::chrono::microseconds(100));
                break;
            case SpanSupply::Take::kEnd:
                end = true;
                break;
        }
    }
    CHECK_FALSE(finished_before_half);
    CHECK(taken.spans == expected.spans);
    CHECK(taken.ticks == expected.total_ticks);
    CHECK(taken.hash == reference.digest.hash);
    REQUIRE(planning.finished());
    CHECK(planning.total_ticks() == expected.total_ticks);
    CHECK(planning.totals()->spans == expected.spans);
    // The tap ran on the planning thread; read after finished() it saw the same spans.
    CHECK(tapped.digest.hash == reference.digest.hash);
}

TEST_CASE(
    "PlanningThread: an error on the planning thread reaches the consumer, cancel ends a waiting "
    "planner",
    "[spsc][planner][threads]") {
    const MachineProfile machine = pen_plotter();
    class FailingTap : public PlanSink {
    public:
        void span(const CoreSpan&) override {
            if (++spans == 5000) throw PlanError("span 5000: refused by the test");
        }
        void pen(const PenEvent&) override {}
        void pause(const PlanPause&) override {}
        std::size_t spans = 0;
    };
    SECTION("error") {
        RandomWalkSource walk(3000, 3);
        FailingTap tap;
        PlanningThread planning(walk, machine, PlanOptions{}, {&tap, {}});
        CoreSpan span;
        std::size_t taken = 0;
        bool threw = false;
        try {
            while (true) {
                const SpanSupply::Take t = planning.take(span);
                if (t == SpanSupply::Take::kSpan) ++taken;
                if (t == SpanSupply::Take::kEnd) break;
                if (t == SpanSupply::Take::kWait)
                    std::this_thread::sleep_for(std::chrono::microseconds(100));
            }
        } catch (const PlanError& e) {
            threw = true;
            CHECK(std::string(e.what()) == "span 5000: refused by the test");
        }
        CHECK(threw);
        CHECK(taken < 5000);
        CHECK_FALSE(planning.totals().has_value());
    }
    SECTION("cancel") {
        RandomWalkSource walk(3000, 3);
        PlanningThread planning(walk, machine, PlanOptions{}, {});
        while (planning.queued() < PlanningThread::kCapacity && !planning.finished()) {
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        REQUIRE(planning.queued() == PlanningThread::kCapacity);
        planning.cancel();  // the planner waits on the full queue: it ends at its next look
        while (!planning.finished()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
        CHECK_FALSE(planning.totals().has_value());
        CoreSpan span;
        CHECK_THROWS(planning.take(span));
    }
}
