// What a plan hands its sink, reduced to a few numbers a test can compare: two plans that
// must be the same, or spans that crossed a queue.
#pragma once

#include <cstdint>

#include "pathstream/host/planner.hpp"

namespace pathstream::host::test {

/// Spans, their ticks and an FNV-1a hash of every field the device gets.
struct Digest {
    std::size_t spans = 0;
    std::uint64_t ticks = 0;
    std::uint64_t hash = 1469598103934665603ull;
    void mix(std::int64_t v) {
        hash ^= static_cast<std::uint64_t>(v);
        hash *= 1099511628211ull;
    }
    void add(const CoreSpan& s) {
        ++spans;
        ticks += s.ticks;
        mix(s.ticks);
        mix(static_cast<std::int64_t>(s.subpath));
        mix(s.pen_down ? 1 : 0);
        mix(s.pause_after ? 1 : 0);
        for (const auto& c : s.control) {
            for (const std::int32_t v : c) mix(v);
        }
    }
};

/// A sink that digests the spans, and the pen events (their ticks and states) apart from them.
class DigestSink : public PlanSink {
public:
    void span(const CoreSpan& s) override { digest.add(s); }
    void pen(const PenEvent& e) override {
        ++pens;
        pen_digest.mix(static_cast<std::int64_t>(e.tick));
        pen_digest.mix(e.down ? 1 : 0);
    }
    void pause(const PlanPause&) override { ++pauses; }
    Digest digest;
    Digest pen_digest;  ///< only its hash is used
    std::size_t pens = 0, pauses = 0;
};

}  // namespace pathstream::host::test
