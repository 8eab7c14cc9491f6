// The handoff between plan_stream's planning and its per-tick check on a second thread: two
// real threads (run under ThreadSanitizer, tag [threads]), a seeded single-thread interleaving
// against a model, and plan_stream with the check on its own thread against one thread.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "pathstream/host/handoff_worker.hpp"
#include "pathstream/host/planner.hpp"
#include "pen_plotter_profile.hpp"
#include "plan_digest.hpp"
#include "random_walk_source.hpp"

using namespace pathstream::host;
using pathstream::host::test::DigestSink;
using pathstream::host::test::pen_plotter;
using pathstream::host::test::RandomWalkSource;

namespace {

// A piece of work whose parts must all come from the same submission: a torn or stale one
// shows in the job's sum.
struct Work {
    std::uint64_t sequence = 0;
    std::vector<std::uint64_t> values;
};

void fill(Work& w, std::uint64_t sequence) {
    w.sequence = sequence;
    w.values.assign(16 + sequence % 48, 0);
    for (std::size_t i = 0; i < w.values.size(); ++i) w.values[i] = sequence * 1000 + i;
}

// The job: checks the work is whole, fails every seventh, throws on every fiftieth.
bool verdict_for(std::uint64_t sequence) {
    return sequence % 7 != 3;
}
bool throws_for(std::uint64_t sequence) {
    return sequence % 50 == 49;
}

struct Job {
    std::vector<std::uint64_t> seen;  // the job side's alone; read after the worker is gone
    bool torn = false;
    bool operator()(const Work& w) {
        seen.push_back(w.sequence);
        if (w.values.size() != 16 + w.sequence % 48) torn = true;
        for (std::size_t i = 0; i < w.values.size(); ++i)
            torn = torn || w.values[i] != w.sequence * 1000 + i;
        if (throws_for(w.sequence)) throw std::runtime_error("job " + std::to_string(w.sequence));
        return verdict_for(w.sequence);
    }
};

// What collect() says for `sequence`, checked against the model (verdict or exception).
void expect_collected(HandoffWorker<Work>& worker, Work& back, std::uint64_t sequence) {
    if (throws_for(sequence)) {
        CHECK_THROWS_WITH(worker.collect(back), "job " + std::to_string(sequence));
    } else {
        CHECK(worker.collect(back) == verdict_for(sequence));
    }
    CHECK(back.sequence == sequence);  // the work comes back as the job saw it
    CHECK_FALSE(worker.busy());
}

}  // namespace

TEST_CASE(
    "HandoffWorker: the caller and the job's thread pass every piece of work once, in order, whole",
    "[handoff][threads]") {
    constexpr std::uint64_t kJobs = 3000;
    Job job;
    {
        HandoffWorker<Work> worker([&job](const Work& w) { return job(w); },
                                   HandoffWorker<Work>::Mode::kThread);
        Work next, back;
        fill(next, 0);
        worker.submit(next);
        for (std::uint64_t s = 1; s <= kJobs; ++s) {
            // The next piece is prepared while the job runs on the last one, as plan_stream
            // plans a window while the one before is checked.
            fill(next, s);
            expect_collected(worker, back, s - 1);
            if (s < kJobs) worker.submit(next);
        }
        CHECK(worker.jobs_finished() == kJobs);
    }
    REQUIRE(job.seen.size() == kJobs);
    for (std::uint64_t s = 0; s < kJobs; ++s) CHECK(job.seen[s] == s);
    CHECK_FALSE(job.torn);
}

TEST_CASE("HandoffWorker: the destructor lets the job in progress finish and joins its thread",
          "[handoff][threads]") {
    std::atomic<bool> started{false}, ended{false};
    {
        HandoffWorker<Work> worker(
            [&](const Work&) {
                started.store(true);
                std::this_thread::sleep_for(std::chrono::milliseconds(30));
                ended.store(true);
                return true;
            },
            HandoffWorker<Work>::Mode::kThread);
        Work w;
        fill(w, 1);
        worker.submit(w);
        while (!started.load()) std::this_thread::yield();
    }  // never collected
    CHECK(ended.load());
}

TEST_CASE(
    "HandoffWorker: a seeded interleaving of submits, job steps and collects follows the model",
    "[handoff]") {
    const char* env = std::getenv("PATHSTREAM_HANDOFF_SEEDS");
    const int seeds = env != nullptr ? std::max(1, std::atoi(env)) : 200;
    for (int seed = 1; seed <= seeds; ++seed) {
        INFO("seed " << seed << " (PATHSTREAM_HANDOFF_SEEDS=" << seeds << ")");
        std::mt19937_64 rng(static_cast<std::uint64_t>(seed));
        Job job;
        HandoffWorker<Work> worker([&job](const Work& w) { return job(w); },
                                   HandoffWorker<Work>::Mode::kCaller);
        Work next, back;
        std::uint64_t submitted = 0, collected = 0;
        bool ran = false;  // the model: the job ran on the submitted work
        for (int action = 0; action < 400; ++action) {
            if (!worker.busy()) {
                fill(next, submitted);
                worker.submit(next);
                ++submitted;
                ran = false;
                continue;
            }
            switch (rng() % 3) {
                case 0:  // the job's side gets its turn: it runs once per submission
                    CHECK(worker.step() == !ran);
                    ran = true;
                    break;
                case 1:
                    CHECK(worker.ready() == ran);
                    break;
                default:  // collect runs the job itself if its side had no turn yet
                    expect_collected(worker, back, submitted - 1);
                    ++collected;
                    break;
            }
            CHECK(worker.jobs_finished() == (ran || !worker.busy() ? submitted : submitted - 1));
        }
        REQUIRE(job.seen.size() == (worker.busy() && !ran ? submitted - 1 : submitted));
        for (std::size_t s = 0; s < job.seen.size(); ++s) CHECK(job.seen[s] == s);
        CHECK_FALSE(job.torn);
        CHECK(collected + (worker.busy() ? 1 : 0) == submitted);
    }
}

TEST_CASE("plan_stream with the check on its own thread hands the sink what one thread does",
          "[handoff][planner][stream][threads]") {
    const pathstream::host::MachineProfile machine = pen_plotter();
    // Small windows: many handoffs, each window planned while the one before is checked.
    for (const std::size_t window : {64u, 2048u}) {
        INFO("windows of " << window << " segments");
        PlanOptions threaded, single;
        threaded.window_segments = single.window_segments = window;
        single.check_on_thread = false;
        RandomWalkSource walk_a(3000, 11), walk_b(3000, 11);
        DigestSink a, b;
        PlanStats stats_a, stats_b;
        const PlanTotals ta = plan_stream(walk_a, machine, threaded, a, &stats_a);
        const PlanTotals tb = plan_stream(walk_b, machine, single, b, &stats_b);
        CHECK(ta.spans == tb.spans);
        CHECK(ta.total_ticks == tb.total_ticks);
        CHECK(a.digest.spans == ta.spans);
        CHECK(a.digest.hash == b.digest.hash);
        CHECK(a.pens == b.pens);
        CHECK(a.pen_digest.hash == b.pen_digest.hash);
        CHECK(a.pauses == b.pauses);
        CHECK(stats_a.replans == stats_b.replans);
    }
}
