#include "plan_scaling.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <limits>
#include <new>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "plan_paths.hpp"

namespace pathstream::bench {

std::array<double, 2> RandomWalk::next() {
    const std::array<double, 2> at{x_, y_};
    heading_ += turn_(rng_);
    x_ += 1.5 * std::cos(heading_);
    y_ += 1.5 * std::sin(heading_);
    if (std::fabs(x_) > 100 || std::fabs(y_) > 100) heading_ = std::atan2(-y_, -x_) + turn_(rng_);
    return at;
}

namespace {

/// What a child writes to its pipe: once after planning, once after the check.
struct ChildReport {
    int phase = 0;  ///< 1 planned, 2 checked
    std::size_t segments = 0, spans = 0;
    double plan_seconds = 0, plan_cpu_seconds = 0, check_seconds = 0;
    int runs = 0;
    double input_mb = 0, plan_peak_mb = 0, peak_mb = 0;
    bool check_passed = false;
    char message[240] = {};
};

constexpr int kExitPlanFailed = 3, kExitOutOfMemory = 4;
constexpr int kMaxRuns = 5;           ///< plans per size at most...
constexpr double kRunsSeconds = 1.0;  ///< ...while they have taken less than this in all

/// CPU time of this process (the child: planning is single-threaded), s.
double cpu_seconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// A field of /proc/self/status in MB ("VmRSS", "VmHWM"), 0 if absent.
double status_mb(const char* field) {
    std::ifstream in("/proc/self/status");
    std::string line;
    const std::string key = std::string(field) + ":";
    while (std::getline(in, line)) {
        if (line.compare(0, key.size(), key) == 0) {
            std::istringstream values(line.substr(key.size()));
            double kb = 0;
            values >> kb;
            return kb / 1024;
        }
    }
    return 0;
}

double load_average() {
    std::ifstream in("/proc/loadavg");
    double one = 0;
    in >> one;
    return one;
}

void send(int fd, const ChildReport& report) {
    const char* at = reinterpret_cast<const char*>(&report);
    std::size_t left = sizeof report;
    while (left > 0) {
        const ssize_t n = write(fd, at, left);
        if (n <= 0) return;
        at += n;
        left -= static_cast<std::size_t>(n);
    }
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// The random walk of wander_path(n), made one segment at a time (the open B-spline's Bezier
/// windows, phantom end points included), so that the input takes no memory either.
class WanderSource : public host::SegmentSource {
public:
    explicit WanderSource(std::size_t points) : points_(points) { rewind(); }
    bool next(host::BezierSegment& out) override {
        // Windows over P(-1) = 2 P0 - P1, P0 .. P(n-1), P(n) = 2 P(n-1) - P(n-2).
        if (emitted_ + 1 >= points_) return false;
        while (window_.size() < 4) window_.push_back(point(window_index_++));
        const auto& q = window_;
        out.p = {host::PathPoint{(q[0][0] + 4 * q[1][0] + q[2][0]) / 6,
                                 (q[0][1] + 4 * q[1][1] + q[2][1]) / 6},
                 host::PathPoint{(4 * q[1][0] + 2 * q[2][0]) / 6, (4 * q[1][1] + 2 * q[2][1]) / 6},
                 host::PathPoint{(2 * q[1][0] + 4 * q[2][0]) / 6, (2 * q[1][1] + 4 * q[2][1]) / 6},
                 host::PathPoint{(q[1][0] + 4 * q[2][0] + q[3][0]) / 6,
                                 (q[1][1] + 4 * q[2][1] + q[3][1]) / 6}};
        if (emitted_ > 0) out.p[0] = last_end_;  // joints shared exactly
        last_end_ = out.p[3];
        out.pen_down = true;
        window_.erase(window_.begin());
        ++emitted_;
        return true;
    }
    bool rewind() override {
        walk_ = RandomWalk{};
        made_.clear();
        window_.clear();
        window_index_ = -1;
        emitted_ = 0;
        return true;
    }
    std::size_t size_hint() const override { return points_ > 0 ? points_ - 1 : 0; }

private:
    /// Walk point i (i = -1 and i = n are the phantom ends), generated in order.
    std::array<double, 2> point(long i) {
        const long n = static_cast<long>(points_);
        if (i < 0) {
            const auto p0 = walk(0), p1 = walk(1);
            return {2 * p0[0] - p1[0], 2 * p0[1] - p1[1]};
        }
        if (i >= n) {
            const auto a = walk(static_cast<std::size_t>(n - 1)),
                       b = walk(static_cast<std::size_t>(n - 2));
            return {2 * a[0] - b[0], 2 * a[1] - b[1]};
        }
        return walk(static_cast<std::size_t>(i));
    }
    /// Points of the walk, the last few kept.
    std::array<double, 2> walk(std::size_t i) {
        while (made_.empty() || made_.back().first < i) {
            const std::size_t k = made_.empty() ? 0 : made_.back().first + 1;
            made_.push_back({k, walk_.next()});
            if (made_.size() > 4) made_.erase(made_.begin());
        }
        for (const auto& [k, p] : made_) {
            if (k == i) return p;
        }
        return made_.back().second;
    }

    std::size_t points_;
    RandomWalk walk_;
    std::vector<std::pair<std::size_t, std::array<double, 2>>> made_;
    std::vector<std::array<double, 2>> window_;
    long window_index_ = -1;
    std::size_t emitted_ = 0;
    host::PathPoint last_end_;
};

/// Takes a streamed plan and keeps only what the report needs: the count, and whether every
/// span starts where the last one ended.
class CountingSink : public host::PlanSink {
public:
    void span(const host::CoreSpan& s) override {
        ++spans;
        if (!last.empty()) {
            for (std::size_t a = 0; a < s.control.size(); ++a)
                continuous = continuous && s.control[a][0] == last[a];
        }
        last.resize(s.control.size());
        for (std::size_t a = 0; a < s.control.size(); ++a) last[a] = s.control[a][1];
    }
    void pen(const host::PenEvent&) override {}
    void pause(const host::PlanPause&) override {}
    bool restart() override {
        spans = 0;
        last.clear();
        continuous = true;
        return true;
    }
    std::size_t spans = 0;
    std::vector<std::int32_t> last;
    bool continuous = true;
};

/// The child: plan `points` as a stream (the windows check every tick against the limits as
/// they go), report. Never returns.
[[noreturn]] void child(std::size_t points, const ScalingOptions& options,
                        const host::MachineProfile& profile, int fd) {
    alarm(options.timeout_seconds);
#ifndef PATHSTREAM_SANITIZED
    // Sanitizers reserve terabytes of shadow address space up front: under them no ceiling.
    const rlim_t limit = static_cast<rlim_t>(options.memory_limit_mb) << 20;
    const rlimit address_space{limit, limit};
    setrlimit(RLIMIT_AS, &address_space);
#endif
    ChildReport report;
    try {
        WanderSource source(points);
        report.segments = source.size_hint();
        report.input_mb = status_mb("VmRSS");
        // Small sizes are planned several times (best wall time kept): one run of a
        // millisecond-scale plan on a shared machine says more about the scheduler than the
        // planner.
        CountingSink sink;
        report.plan_seconds = std::numeric_limits<double>::infinity();
        const auto started = std::chrono::steady_clock::now();
        for (int run = 0; run < kMaxRuns && (run == 0 || seconds_since(started) < kRunsSeconds);
             ++run) {
            source.rewind();
            sink.restart();
            const double cpu0 = cpu_seconds();
            const auto t0 = std::chrono::steady_clock::now();
            (void)host::plan_stream(source, profile, host::PlanOptions{}, sink);
            const double wall = seconds_since(t0);
            if (wall < report.plan_seconds) {
                report.plan_seconds = wall;
                report.plan_cpu_seconds = cpu_seconds() - cpu0;
            }
            report.runs = run + 1;
        }
        report.plan_peak_mb = status_mb("VmHWM");
        report.spans = sink.spans;
        report.phase = 1;
        send(fd, report);
        // plan_stream checked every tick against the limits (it throws otherwise); what is
        // left to check here is that the spans chain.
        report.check_seconds = 0;
        report.peak_mb = status_mb("VmHWM");
        report.check_passed = sink.continuous;
        report.phase = 2;
        send(fd, report);
        _exit(0);
    } catch (const std::bad_alloc&) {
        _exit(kExitOutOfMemory);
    } catch (const std::exception& e) {
        std::snprintf(report.message, sizeof report.message, "%s", e.what());
        send(fd, report);
        _exit(kExitPlanFailed);
    }
}

ScalingRow run_one(std::size_t points, const ScalingOptions& options,
                   const host::MachineProfile& profile) {
    ScalingRow row;
    row.points = points;
    row.load_start = load_average();
    int fds[2];
    if (pipe(fds) != 0) {
        row.status = "pipe failed";
        return row;
    }
    std::fflush(stdout);
    std::fflush(stderr);
    const pid_t pid = fork();
    if (pid < 0) {
        row.status = "fork failed";
        close(fds[0]);
        close(fds[1]);
        return row;
    }
    if (pid == 0) {
        close(fds[0]);
        child(points, options, profile, fds[1]);
    }
    close(fds[1]);
    ChildReport report, last;
    std::size_t got = 0;
    char* into = reinterpret_cast<char*>(&report);
    for (;;) {  // reports arrive whole or not at all (the child writes each in one go)
        const ssize_t n = read(fds[0], into + got, sizeof report - got);
        if (n <= 0) break;
        got += static_cast<std::size_t>(n);
        if (got == sizeof report) {
            last = report;
            got = 0;
        }
    }
    close(fds[0]);
    int status = 0;
    rusage usage{};
    while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
    }
    row.load_end = load_average();
    row.segments = last.segments;
    row.spans = last.spans;
    row.planned = last.phase >= 1;
    row.checked = last.phase >= 2;
    row.plan_seconds = last.plan_seconds;
    row.plan_cpu_seconds = last.plan_cpu_seconds;
    row.runs = last.runs;
    row.check_seconds = last.check_seconds;
    row.input_mb = last.input_mb;
    row.plan_peak_mb = last.plan_peak_mb;
    row.check_passed = last.check_passed;
    // The child's own peak (wait4 gives this child's rusage alone), whatever phase it reached.
    row.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024;
    if (WIFSIGNALED(status)) {
        row.status = WTERMSIG(status) == SIGALRM
                         ? (row.planned ? "check timeout" : "timeout")
                         : "killed by signal " + std::to_string(WTERMSIG(status));
    } else if (WEXITSTATUS(status) == kExitOutOfMemory) {
        row.status = "out of memory";
    } else if (WEXITSTATUS(status) == kExitPlanFailed) {
        row.status = std::string(row.planned ? "check failed: " : "plan failed: ") + last.message;
    } else if (WEXITSTATUS(status) != 0) {
        row.status = "exit " + std::to_string(WEXITSTATUS(status));
    } else {
        row.status = row.check_passed ? "ok" : "check failed";
    }
    return row;
}

}  // namespace

std::vector<ScalingRow> run_scaling(const ScalingOptions& options,
                                    const host::MachineProfile& profile) {
    std::vector<ScalingRow> rows;
    for (std::size_t points : {1'000ul, 10'000ul, 100'000ul, 1'000'000ul}) {
        if (points > options.max_segments) break;
        rows.push_back(run_one(points, options, profile));
    }
    return rows;
}

bool scaling_passed(const std::vector<ScalingRow>& rows) {
    for (const ScalingRow& r : rows) {
        if (r.status.rfind("plan failed", 0) == 0 || r.status.rfind("check failed", 0) == 0 ||
            r.status.rfind("killed", 0) == 0 || r.status.rfind("exit", 0) == 0) {
            return false;
        }
    }
    return true;
}

void print_scaling(const std::vector<ScalingRow>& rows, const ScalingOptions& options,
                   bool markdown) {
#ifdef PATHSTREAM_SANITIZED
    const char* const address_note = " (not applied: sanitizer build)";
#else
    const char* const address_note = "";
#endif
    std::printf(
        "\nscaling: smooth random-walk B-spline of N points, each size planned in its own process "
        "(limit %u s, %zu MB address space%s); wall times, machine load = 1-minute load "
        "average\n",
        options.timeout_seconds, options.memory_limit_mb, address_note);
    std::printf(
        "targets: 10k segments in <= 50 ms; us/segment within 1.5x of the 1k figure up to 1M; "
        "peak RSS at 1M <= 64 MB and within 1.2x of 10k (printed, not judged)\n\n");
    if (markdown) {
        std::printf(
            "| points | segments | spans | plan s | plan CPU s | us/segment | ratio to 1k | CPU "
            "ratio to 1k | "
            "check s | input MB | plan peak MB | peak MB | load start | load end | status |\n");
        std::printf(
            "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    } else {
        std::printf("%9s %9s %8s %9s %9s %8s %6s %6s %9s %8s %8s %8s %6s %6s  %s\n", "points",
                    "segments", "spans", "plan s", "cpu s", "us/seg", "x 1k", "cpu x", "check s",
                    "input MB", "plan MB", "peak MB", "load0", "load1", "status");
    }
    double base = 0, cpu_base = 0;  // us per segment of the first planned size, wall and CPU
    for (const ScalingRow& r : rows) {
        const double n = static_cast<double>(r.segments);
        const double per_segment = r.planned && r.segments > 0 ? 1e6 * r.plan_seconds / n : 0;
        const double cpu_per_segment =
            r.planned && r.segments > 0 ? 1e6 * r.plan_cpu_seconds / n : 0;
        if (base == 0 && per_segment > 0) base = per_segment, cpu_base = cpu_per_segment;
        char plan[32] = "-", cpu[32] = "-", us[32] = "-", ratio[32] = "-", cpu_ratio[32] = "-",
             check[32] = "-", input[32] = "-", plan_mb[32] = "-";
        if (r.planned) {
            std::snprintf(plan, sizeof plan, "%.3f", r.plan_seconds);
            std::snprintf(cpu, sizeof cpu, "%.3f", r.plan_cpu_seconds);
            std::snprintf(us, sizeof us, "%.1f", per_segment);
            std::snprintf(ratio, sizeof ratio, "%.2f", per_segment / base);
            std::snprintf(cpu_ratio, sizeof cpu_ratio, "%.2f",
                          cpu_base > 0 ? cpu_per_segment / cpu_base : 0);
            std::snprintf(input, sizeof input, "%.1f", r.input_mb);
            std::snprintf(plan_mb, sizeof plan_mb, "%.1f", r.plan_peak_mb);
        }
        if (r.checked)
            std::snprintf(check, sizeof check, "%s", r.check_seconds > 0 ? "?" : "in plan");
        const std::string segments = r.planned ? std::to_string(r.segments) : "-";
        const std::string spans = r.planned ? std::to_string(r.spans) : "-";
        if (markdown) {
            std::printf(
                "| %zu | %s | %s | %s | %s | %s | %s | %s | %s | %s | %s | %.1f | %.2f | %.2f | %s "
                "|\n",
                r.points, segments.c_str(), spans.c_str(), plan, cpu, us, ratio, cpu_ratio, check,
                input, plan_mb, r.peak_mb, r.load_start, r.load_end, r.status.c_str());
        } else {
            std::printf("%9zu %9s %8s %9s %9s %8s %6s %6s %9s %8s %8s %8.1f %6.2f %6.2f  %s\n",
                        r.points, segments.c_str(), spans.c_str(), plan, cpu, us, ratio, cpu_ratio,
                        check, input, plan_mb, r.peak_mb, r.load_start, r.load_end,
                        r.status.c_str());
        }
    }
    std::printf(
        "\nplan s: best of up to %d runs while under %g s in all (1 run for large sizes); cpu s: "
        "the "
        "child's CPU time for that run\n",
        kMaxRuns, kRunsSeconds);
}

}  // namespace pathstream::bench
