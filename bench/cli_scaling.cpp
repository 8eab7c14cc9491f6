#include "cli_scaling.hpp"

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace pathstream::bench {

namespace {

double load_average() {
    std::ifstream in("/proc/loadavg");
    double one = 0;
    in >> one;
    return one;
}

/// The walk of `points` points as a JSON path file (B-spline, mm to 1 nm).
void write_walk(std::size_t points, const std::string& file) {
    std::FILE* out = std::fopen(file.c_str(), "w");
    if (out == nullptr) return;
    std::fputs("{\"basis\": \"bspline\", \"points\": [", out);
    RandomWalk walk;
    for (std::size_t i = 0; i < points; ++i) {
        const auto p = walk.next();
        std::fprintf(out, "%s[%.6f, %.6f]", i == 0 ? "" : ", ", p[0], p[1]);
    }
    std::fputs("]}\n", out);
    std::fclose(out);
}

/// Runs one command in a child with the limits; fills the row's figures.
void run_command(CliRow& row, const ScalingOptions& options, const std::string& binary,
                 const std::string& file, const std::string& machine) {
    row.load_start = load_average();
    std::fflush(stdout);
    std::fflush(stderr);
    const auto t0 = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid < 0) {
        row.status = "fork failed";
        return;
    }
    if (pid == 0) {
        alarm(options.timeout_seconds);  // kept across exec
#ifndef PATHSTREAM_SANITIZED
        const rlim_t limit = static_cast<rlim_t>(options.memory_limit_mb) << 20;
        const rlimit address_space{limit, limit};
        setrlimit(RLIMIT_AS, &address_space);
#endif
        std::FILE* null = std::fopen("/dev/null", "w");
        if (null != nullptr) {
            dup2(fileno(null), STDOUT_FILENO);
            dup2(fileno(null), STDERR_FILENO);
        }
        execl(binary.c_str(), binary.c_str(), row.command.c_str(), file.c_str(), "-m",
              machine.c_str(), static_cast<char*>(nullptr));
        _exit(127);
    }
    int status = 0;
    rusage usage{};
    while (wait4(pid, &status, 0, &usage) < 0 && errno == EINTR) {
    }
    row.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    row.cpu_seconds = static_cast<double>(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                      1e-6 * static_cast<double>(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    row.peak_mb = static_cast<double>(usage.ru_maxrss) / 1024;
    row.load_end = load_average();
    if (WIFSIGNALED(status)) {
        row.status = WTERMSIG(status) == SIGALRM
                         ? "timeout"
                         : "killed by signal " + std::to_string(WTERMSIG(status));
    } else {
        row.status =
            WEXITSTATUS(status) == 0 ? "ok" : "exit " + std::to_string(WEXITSTATUS(status));
    }
}

}  // namespace

std::vector<CliRow> run_cli_scaling(const ScalingOptions& options, const std::string& binary,
                                    const std::string& machine) {
    std::vector<CliRow> rows;
    char pattern[] = "/tmp/bench_plan_cli_XXXXXX";
    const char* dir = mkdtemp(pattern);
    if (dir == nullptr) return rows;
    for (std::size_t points : {1'000ul, 10'000ul, 100'000ul, 1'000'000ul}) {
        if (points > options.max_segments) break;
        const std::string file = std::string(dir) + "/walk_" + std::to_string(points) + ".json";
        write_walk(points, file);
        std::error_code error;
        const double mb = static_cast<double>(std::filesystem::file_size(file, error)) / (1 << 20);
        for (const char* command : {"plan", "sim"}) {
            CliRow row;
            row.points = points;
            row.command = command;
            row.file_mb = error ? 0 : mb;
            run_command(row, options, binary, file, machine);
            rows.push_back(row);
        }
        std::filesystem::remove(file, error);
    }
    std::error_code error;
    std::filesystem::remove_all(dir, error);
    return rows;
}

void print_cli_scaling(const std::vector<CliRow>& rows, const std::vector<ScalingRow>& stream_rows,
                       bool markdown) {
    std::printf(
        "\ncommands: the same walks as JSON files through `pathstream plan FILE -m "
        "pen_plotter.json` and `pathstream sim FILE -m pen_plotter.json`, each in its own "
        "process (CPU = user + system of the child, peak = its maximum RSS); x stream = the "
        "command's CPU over plan_stream's CPU for the size above\n");
    std::printf(
        "targets: plan of 10k within 1.5x of plan_stream's CPU; plan of 1M at most 64 MB + 100 "
        "bytes a point; CPU per point flat within 1.5x from 1k to 1M (printed, not judged)\n\n");
    if (markdown) {
        std::printf(
            "| command | points | file MB | wall s | CPU s | us/point | x 1k | x stream | peak MB "
            "| load start | load end | status |\n");
        std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n");
    } else {
        std::printf("%-7s %9s %8s %8s %8s %8s %6s %8s %8s %6s %6s  %s\n", "command", "points",
                    "file MB", "wall s", "cpu s", "us/pt", "x 1k", "x stream", "peak MB", "load0",
                    "load1", "status");
    }
    for (const CliRow& r : rows) {
        const double per_point = 1e6 * r.cpu_seconds / static_cast<double>(r.points);
        double base = 0;
        for (const CliRow& b : rows) {
            if (b.command == r.command && b.status == "ok") {
                base = 1e6 * b.cpu_seconds / static_cast<double>(b.points);
                break;
            }
        }
        char stream[32] = "-";
        for (const ScalingRow& s : stream_rows) {
            if (r.command == "plan" && s.points == r.points && s.planned && s.plan_cpu_seconds > 0)
                std::snprintf(stream, sizeof stream, "%.2f", r.cpu_seconds / s.plan_cpu_seconds);
        }
        const double x1k = base > 0 ? per_point / base : 0;
        std::printf(markdown
                        ? "| %s | %zu | %.1f | %.3f | %.3f | %.1f | %.2f | %s | %.1f | %.2f | "
                          "%.2f | %s |\n"
                        : "%-7s %9zu %8.1f %8.3f %8.3f %8.1f %6.2f %8s %8.1f %6.2f %6.2f  %s\n",
                    r.command.c_str(), r.points, r.file_mb, r.wall_seconds, r.cpu_seconds,
                    per_point, x1k, stream, r.peak_mb, r.load_start, r.load_end, r.status.c_str());
    }
}

bool cli_scaling_passed(const std::vector<CliRow>& rows) {
    for (const CliRow& r : rows) {
        if (r.status.rfind("exit", 0) == 0 || r.status.rfind("killed", 0) == 0) return false;
    }
    return true;
}

}  // namespace pathstream::bench
