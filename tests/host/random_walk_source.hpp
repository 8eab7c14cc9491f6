// A long job that is never held in memory, for the tests of the windowed planner and of
// streaming while planning.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "pathstream/host/planner.hpp"

namespace pathstream::host::test {

/// A smooth random walk as an open uniform B-spline, given segment by segment (Bezier form of
/// each window of four control points): nothing of the job is held in memory.
class RandomWalkSource : public SegmentSource {
public:
    RandomWalkSource(std::size_t segments, std::uint64_t seed) : segments_(segments), seed_(seed) {
        rewind();
    }
    bool next(BezierSegment& out) override {
        if (made_ >= segments_) return false;
        q_[0] = q_[1];
        q_[1] = q_[2];
        q_[2] = q_[3];
        q_[3] = step();
        out.p = {PathPoint{(q_[0][0] + 4 * q_[1][0] + q_[2][0]) / 6,
                           (q_[0][1] + 4 * q_[1][1] + q_[2][1]) / 6},
                 PathPoint{(4 * q_[1][0] + 2 * q_[2][0]) / 6, (4 * q_[1][1] + 2 * q_[2][1]) / 6},
                 PathPoint{(2 * q_[1][0] + 4 * q_[2][0]) / 6, (2 * q_[1][1] + 4 * q_[2][1]) / 6},
                 PathPoint{(q_[1][0] + 4 * q_[2][0] + q_[3][0]) / 6,
                           (q_[1][1] + 4 * q_[2][1] + q_[3][1]) / 6}};
        if (made_ > 0) out.p[0] = last_end_;  // joints shared exactly
        last_end_ = out.p[3];
        out.pen_down = true;
        ++made_;
        return true;
    }
    bool rewind() override {
        rng_.seed(seed_);
        made_ = 0;
        x_ = y_ = 100;
        dir_ = 0;
        for (auto& q : q_) q = step();
        return true;
    }
    std::size_t size_hint() const override { return segments_; }

private:
    std::array<double, 2> step() {
        dir_ += std::uniform_real_distribution<double>(-0.6, 0.6)(rng_);
        x_ += 1.5 * std::cos(dir_);
        y_ += 1.5 * std::sin(dir_);
        if (x_ < 0 || x_ > 400 || y_ < 0 || y_ > 400) dir_ += 3.14159265358979;
        x_ = std::clamp(x_, 0.0, 400.0);
        y_ = std::clamp(y_, 0.0, 400.0);
        return {std::round(x_ * 1000) / 1000, std::round(y_ * 1000) / 1000};
    }

    std::size_t segments_;
    std::uint64_t seed_;
    std::mt19937_64 rng_;
    std::size_t made_ = 0;
    double x_ = 0, y_ = 0, dir_ = 0;
    std::array<std::array<double, 2>, 4> q_{};
    PathPoint last_end_;
};

}  // namespace pathstream::host::test
