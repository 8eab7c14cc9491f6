// The device stress harness: a task side that sends random valid and invalid batches,
// commands, faults, e-stops and resets (Driver), and a checker of every tick the tick side
// outputs (TickChecker). tests/core/test_device_stress.cpp runs them on two threads (the tick
// as fast as it can) and on one thread interleaved at seeded points.
#pragma once

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/wire_span.hpp"

namespace pathstream::test {

/// Ticks per stress test (--stress-ticks N; default 1,000,000).
extern std::uint64_t g_stress_ticks;

namespace stress {

inline constexpr unsigned kAxes = 2;
inline constexpr std::uint32_t kCapacity = 16;
using Device = device::MotionDevice<kAxes, kCapacity>;
using Status3 = device::DeviceStatus<kAxes>;

/// 1 kHz; 100 LSB per tick and 2 LSB per tick^2 on every axis; no pen-down lead.
inline device::MotionLimits<kAxes> limits() {
    device::MotionLimits<kAxes> l;
    l.tick_hz = 1000;
    for (unsigned a = 0; a < kAxes; ++a) l.axis[a] = {100000, 2000000};
    return l;
}
/// The limits per tick plus the core's one rounding of each setpoint (1 LSB in a step, 2 in
/// a second difference).
inline constexpr std::int64_t kMaxStep = 100 + 1;
inline constexpr std::int64_t kMaxSecond = 2 + 2;

inline bool stopped_at_once(device::DeviceState s) {
    return s == device::DeviceState::kFault || s == device::DeviceState::kEstop;
}
inline bool at_rest_state(device::DeviceState s) {
    return s == device::DeviceState::kIdle || stopped_at_once(s);
}

/// Checks each tick's status as the tick side published it (call it in the tick's context,
/// right after each tick). Keeps the first violation.
class TickChecker {
public:
    /// Also keeps the setpoints of the first `keep` ticks (for torn-read checks afterwards).
    explicit TickChecker(std::size_t keep = 0) : keep_(keep) { positions_.reserve(keep * kAxes); }

    void after_tick(const Status3& s) {
        const device::DeviceState st = s.device_state();
        if (s.tick_count != s.tick_check) fail(s, "status torn in the tick's own context");
        if (positions_.size() < keep_ * kAxes)
            positions_.insert(positions_.end(), s.position, s.position + kAxes);
        if (n_ >= 1) {
            for (unsigned a = 0; a < kAxes; ++a) {
                const std::int64_t step = std::int64_t{s.position[a]} - p1_[a];
                if (std::llabs(step) > kMaxStep) fail(s, "step beyond the velocity limit");
                // No motion while stopped, and the instant stop repeats the last setpoint.
                if (step != 0 && at_rest_state(st) &&
                    (at_rest_state(state1_) || stopped_at_once(st))) {
                    fail(s, "motion in idle, fault or e-stop");
                }
            }
        }
        if (n_ >= 2 && !stopped_at_once(st) && !stopped_at_once(state1_) &&
            !stopped_at_once(state2_)) {
            for (unsigned a = 0; a < kAxes; ++a) {
                const std::int64_t second =
                    std::int64_t{s.position[a]} - 2 * std::int64_t{p1_[a]} + p2_[a];
                if (std::llabs(second) > kMaxSecond)
                    fail(s, "second difference beyond the acceleration limit");
            }
        }
        if (s.paused()) {
            ++paused_ticks_;
            if (st != device::DeviceState::kHolding) fail(s, "paused flag outside holding");
        } else if (paused1_ && st == device::DeviceState::kRunning) {
            ++pauses_resumed_;
        }
        paused1_ = s.paused();
        if (s.path_tick()) {
            ++path_ticks_;
            if (s.span_epoch != s.epoch) fail(s, "a span of an older epoch was executed");
        } else if ((s.outputs & kOutputPenDown) != 0) {
            fail(s, "pen down on a tick that is not a path tick");
        }
        if (st == device::DeviceState::kFault && s.fault() != device::FaultCode::kExternal) {
            fail(s, "a fault the test did not raise");
        }
        if (n_ >= 1 && s.epoch != epoch_) ++epochs_;
        if (s.finished_job != finished_job_) ++jobs_finished_;
        if (st != state1_ || n_ == 0) ++state_changes_;
        if (s.state < 6) ++in_state_[s.state];
        epoch_ = s.epoch;
        finished_job_ = s.finished_job;
        for (unsigned a = 0; a < kAxes; ++a) {
            p2_[a] = p1_[a];
            p1_[a] = s.position[a];
        }
        state2_ = state1_;
        state1_ = st;
        ++n_;
    }

    bool ok() const { return failure_.empty(); }
    const std::string& failure() const { return failure_; }
    std::uint64_t ticks() const { return n_; }
    std::uint64_t path_ticks() const { return path_ticks_; }
    /// Ticks holding at a programmed pause (the status's paused flag).
    std::uint64_t paused_ticks() const { return paused_ticks_; }
    /// Programmed pauses left by a resume (paused, then running).
    std::uint64_t pauses_resumed() const { return pauses_resumed_; }
    std::uint64_t epochs() const { return epochs_; }
    std::uint64_t jobs_finished() const { return jobs_finished_; }
    std::uint64_t state_changes() const { return state_changes_; }
    /// Ticks spent in each DeviceState.
    std::uint64_t ticks_in(device::DeviceState s) const {
        return in_state_[static_cast<unsigned>(s)];
    }
    /// Setpoints of tick k (k < keep, k from 0): positions()[k * kAxes + axis].
    const std::vector<Lsb>& positions() const { return positions_; }

private:
    void fail(const Status3& s, const char* what) {
        if (!failure_.empty()) return;
        std::ostringstream m;
        m << what << " at tick " << n_ << " (state " << s.state << ", setpoints " << s.position[0]
          << ' ' << s.position[1] << ", before " << p1_[0] << ' ' << p1_[1] << ", " << p2_[0] << ' '
          << p2_[1] << ", states before " << static_cast<unsigned>(state1_) << ' '
          << static_cast<unsigned>(state2_) << ", epoch " << s.epoch << ", span epoch "
          << s.span_epoch << ")";
        failure_ = m.str();
    }

    std::size_t keep_;
    std::string failure_;
    std::vector<Lsb> positions_;
    std::uint64_t n_ = 0, path_ticks_ = 0, paused_ticks_ = 0, pauses_resumed_ = 0, epochs_ = 0,
                  jobs_finished_ = 0, state_changes_ = 0;
    bool paused1_ = false;
    std::uint64_t in_state_[6] = {};
    std::int64_t p1_[kAxes] = {}, p2_[kAxes] = {};
    device::DeviceState state1_ = device::DeviceState::kIdle, state2_ = device::DeviceState::kIdle;
    std::uint32_t epoch_ = 0, finished_job_ = 0;
};

/// What the task side did, and the first thing it saw go wrong.
struct DriverCounts {
    std::uint64_t actions = 0, batches_ok = 0, batches_refused = 0, spans_ok = 0,
                  invalid_refused = 0;
    std::uint64_t commands = 0, faults = 0, estops = 0, job_ends_sent = 0, status_reads = 0;
    std::uint64_t pauses_sent = 0;  ///< accepted batches ending in a programmed pause
};

/// The task side: one random action per step(). `between` is passed to accept_batch (the
/// single-thread test runs ticks there). Keeps its own view of where the device's chain ends
/// (position and velocity per axis, reset at every new epoch) so that its valid batches are
/// valid, and checks every answer.
class Driver {
public:
    Driver(Device& d, std::uint64_t seed) : d_(d), rng_(seed) {}

    template <typename Between>
    void step(Between&& between) {
        ++counts_.actions;
        const int r = pick(0, 999);
        if (r < 480) {
            valid_batch(between);
        } else if (r < 560) {
            invalid_batch(between);
        } else if (r < 660) {
            command(device::Command::kStart);
        } else if (r < 700) {
            command(device::Command::kHold);
        } else if (r < 780) {
            command(device::Command::kResume);
        } else if (r < 805) {
            command(device::Command::kStop);
        } else if (r < 860) {
            command(device::Command::kReset);
        } else if (r < 875) {
            ++counts_.faults;
            d_.raise_fault(device::FaultCode::kExternal);
        } else if (r < 890) {
            ++counts_.estops;
            estop_ = true;
            d_.set_estop_input(true);
        } else if (r < 940) {
            if (estop_) {
                estop_ = false;
                d_.set_estop_input(false);
            }
        } else if (r < 960) {
            const std::uint16_t v =
                static_cast<std::uint16_t>(pick(0, 1) == 0 ? 0 : pick(6, 0xFFFF));
            if (d_.command(static_cast<device::Command>(v)) != Status::kUnknownCommand)
                fail("unknown command accepted");
        } else {
            read_status();
        }
    }

    /// Reads the status whole; a torn read would show tick_count != tick_check. Keeps up to
    /// `keep` (tick, setpoints) samples for a comparison with the tick side's record.
    Status3 read_status() {
        const Status3 s = d_.status();
        ++counts_.status_reads;
        if (s.tick_count != s.tick_check) fail("torn status read");
        if (samples_.size() < kMaxSamples && s.tick_count != 0) {
            samples_.push_back({s.tick_count - 1, {s.position[0], s.position[1]}});
        }
        return s;
    }

    const DriverCounts& counts() const { return counts_; }
    const std::string& failure() const { return failure_; }
    struct Sample {
        std::uint32_t tick;
        Lsb position[kAxes];
    };
    const std::vector<Sample>& samples() const { return samples_; }

private:
    static constexpr std::size_t kMaxSamples = 1u << 20;
    static constexpr std::int32_t kMaxV = 90;        // LSB per tick
    static constexpr std::int64_t kFar = 5'000'000;  // drift back toward 0 beyond this

    int pick(int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng_); }

    void fail(const std::string& what) {
        if (failure_.empty()) failure_ = what + " (action " + std::to_string(counts_.actions) + ")";
    }

    // A new epoch: the device's chain restarts at rest at the epoch's origin. (epoch_ is the
    // epoch of the last accepted batch, so a newer one in the status means a restart.)
    void sync(const Status3& s) {
        if (have_epoch_ && s.epoch == epoch_) return;
        have_epoch_ = true;
        epoch_ = s.epoch;
        for (unsigned a = 0; a < kAxes; ++a) {
            at_[a] = s.origin[a];
            v_[a] = 0;
        }
        n_ = 1;
        ending_ = false;
    }

    // The next span of the random walk from the chain's end: constant acceleration over n
    // ticks (at most 2 LSB per tick^2), velocity within kMaxV, or braking to rest.
    device::WireSpan next_span(std::int64_t (&at)[kAxes], std::int32_t (&v)[kAxes],
                               std::uint32_t& previous_ticks) {
        static const std::uint32_t kLengths[] = {2, 4, 8, 16, 32, 64};
        device::WireSpan w;
        w.ticks = kLengths[pick(0, 5)];
        const std::int32_t n = static_cast<std::int32_t>(w.ticks);
        w.outputs = pick(0, 3) != 0 ? kOutputPenDown : std::uint8_t{0};
        for (unsigned a = 0; a < kAxes; ++a) {
            std::int32_t v1;
            if (ending_) {
                v1 = v[a] - std::clamp(v[a], -2 * n, 2 * n);
            } else {
                // A random acceleration, turned back toward 0 far from it (positions stay in
                // range).
                const int dv = at[a] > kFar    ? pick(-2 * n, 0)
                               : at[a] < -kFar ? pick(0, 2 * n)
                                               : pick(-2 * n, 2 * n);
                v1 = std::clamp(v[a] + dv, -kMaxV, kMaxV);
            }
            w.start_tangent[a] = v[a] * n;
            w.end_tangent[a] = v1 * n;
            at[a] += static_cast<std::int64_t>(v[a] + v1) * n / 2;
            w.end[a] = static_cast<std::int32_t>(at[a]);
            v[a] = v1;
        }
        // T0 travels only when it differs from the previous T1 (another span length).
        w.flags = w.ticks == previous_ticks ? device::kWireContinueTangent : std::uint8_t{0};
        previous_ticks = w.ticks;
        return w;
    }

    // `bad_flag`: the index of a span whose flags byte gets an unknown bit (the encoder
    // refuses to write one), or -1.
    template <typename Between>
    Status send(std::uint32_t first, const std::vector<device::WireSpan>& spans, Between& between,
                int bad_flag = -1) {
        std::vector<std::uint8_t> bytes;
        for (std::size_t i = 0; i < spans.size(); ++i) {
            std::uint8_t b[4 + 12 * kAxes];
            const std::size_t n = device::encode_wire_span(spans[i], kAxes, b, sizeof b);
            if (n == 0) {
                fail("a span the test made cannot be encoded");
                return Status::kBadBatch;
            }
            if (static_cast<int>(i) == bad_flag) b[2] = static_cast<std::uint8_t>(b[2] | 0x80u);
            bytes.insert(bytes.end(), b, b + n);
        }
        return d_.accept_batch(first, static_cast<std::uint16_t>(spans.size()), bytes.data(),
                               bytes.size(), between);
    }

    template <typename Between>
    void valid_batch(Between& between) {
        const Status3 s = read_status();
        sync(s);
        std::int64_t at[kAxes] = {at_[0], at_[1]};
        std::int32_t v[kAxes] = {v_[0], v_[1]};
        std::uint32_t n = n_;
        if (!ending_ && pick(0, 19) == 0) ending_ = true;
        const int count = pick(1, 12);
        std::vector<device::WireSpan> spans;
        bool job_end = false, pause = false;
        for (int i = 0; i < count && !job_end; ++i) {
            spans.push_back(next_span(at, v, n));
            if (ending_ && v[0] == 0 && v[1] == 0) {
                // At rest: a job end, or a programmed pause (the device holds there until a
                // resume, then the job goes on from rest), or neither.
                const int what = pick(0, 9);
                if (what < 5) {
                    spans.back().flags =
                        static_cast<std::uint8_t>(spans.back().flags | device::kWireJobEnd);
                } else if (what < 8) {
                    spans.back().flags =
                        static_cast<std::uint8_t>(spans.back().flags | device::kWirePause);
                    pause = true;
                }
                job_end = true;
            }
        }
        const std::uint32_t first = d_.last_accepted_sequence() + 1;
        const Status st = send(first, spans, between);
        if (st == Status::kOk) {
            ++counts_.batches_ok;
            counts_.spans_ok += spans.size();
            if (job_end && (spans.back().flags & device::kWireJobEnd) != 0) ++counts_.job_ends_sent;
            if (pause) ++counts_.pauses_sent;
            for (unsigned a = 0; a < kAxes; ++a) {
                at_[a] = at[a];
                v_[a] = v[a];
            }
            n_ = n;
            // The receiver may have taken a newer epoch in this call (the batch was valid from
            // there too): the chain is now this batch's end in that epoch.
            epoch_ = d_.receiver().producer_epoch();
            if (job_end) ending_ = false;
            if (d_.last_accepted_sequence() != first + spans.size() - 1)
                fail("accepted batch not counted");
            return;
        }
        ++counts_.batches_refused;
        if (d_.last_accepted_sequence() != first - 1) fail("refused batch changed the sequence");
        if (st == Status::kQueueFull || st == Status::kWrongState) return;
        // Refused for its content: only possible when the tick dropped the queue meanwhile (a
        // new epoch restarts the chain at rest elsewhere).
        if (read_status().epoch == s.epoch)
            fail(std::string("valid batch refused: ") + status_name(st));
    }

    template <typename Between>
    void invalid_batch(Between& between) {
        const Status3 s = read_status();
        sync(s);
        std::int64_t at[kAxes] = {at_[0], at_[1]};
        std::int32_t v[kAxes] = {v_[0], v_[1]};
        std::uint32_t n0 = n_;
        std::vector<device::WireSpan> spans;
        const int count = pick(1, 6);
        for (int i = 0; i < count; ++i) spans.push_back(next_span(at, v, n0));
        std::uint32_t first = d_.last_accepted_sequence() + 1;
        const int index = pick(0, count - 1);
        int bad_flag = -1;
        device::WireSpan& w = spans[static_cast<std::size_t>(index)];
        const std::int32_t n = static_cast<std::int32_t>(w.ticks);
        switch (pick(0, 5)) {
            case 0:  // a gap in the sequence numbers
                first += 3;
                break;
            case 1:  // twice the acceleration limit inside the span
                w.end_tangent[0] = w.start_tangent[0] + (w.start_tangent[0] > 0 ? -4 : 4) * n * n;
                break;
            case 2:  // a velocity step of 20 LSB per tick at the span's start
                w.flags = 0;
                for (unsigned a = 0; a < kAxes; ++a)
                    w.start_tangent[a] = w.start_tangent[a] + 20 * n;
                break;
            case 3: {  // a job end while moving
                spans.resize(1);
                device::WireSpan& j = spans[0];
                const std::int32_t v0 = v_[0];
                const std::int32_t v1 = v0 >= 0 ? v0 + 2 : v0 - 2;
                j.end_tangent[0] = v1 * static_cast<std::int32_t>(j.ticks);
                j.end[0] = static_cast<std::int32_t>(at_[0] + static_cast<std::int64_t>(v0 + v1) *
                                                                  j.ticks / 2);
                j.flags = device::kWireJobEnd;  // T0 sent: v0 over this span's length
                break;
            }
            case 4: {  // a pause while moving (as the job end above)
                spans.resize(1);
                device::WireSpan& p = spans[0];
                const std::int32_t v0 = v_[0];
                const std::int32_t v1 = v0 >= 0 ? v0 + 2 : v0 - 2;
                p.end_tangent[0] = v1 * static_cast<std::int32_t>(p.ticks);
                p.end[0] = static_cast<std::int32_t>(at_[0] + static_cast<std::int64_t>(v0 + v1) *
                                                                  p.ticks / 2);
                p.flags = device::kWirePause;
                break;
            }
            default:  // an unknown flag
                bad_flag = index;
                break;
        }
        const std::uint32_t before = d_.last_accepted_sequence();
        const Status st = send(first, spans, between, bad_flag);
        if (st == Status::kOk) fail("invalid batch accepted");
        if (d_.last_accepted_sequence() != before) fail("invalid batch changed the sequence");
        ++counts_.invalid_refused;
    }

    void command(device::Command c) {
        ++counts_.commands;
        const Status st = d_.command(c);
        if (st != Status::kOk && st != Status::kWrongState && st != Status::kNothingToResume) {
            fail(std::string("command answered ") + status_name(st));
        }
    }

    Device& d_;
    std::mt19937_64 rng_;
    DriverCounts counts_;
    std::string failure_;
    std::vector<Sample> samples_;
    bool have_epoch_ = false;
    std::uint32_t epoch_ = 0;
    std::int64_t at_[kAxes] = {};
    std::int32_t v_[kAxes] = {};
    std::uint32_t n_ = 1;  // ticks of the chain's last span
    bool ending_ = false;
    bool estop_ = false;
};

}  // namespace stress
}  // namespace pathstream::test
