// bench_mqtt: what a fleet costs on one broker (docs/mqtt.md, "Figures"). A real mosquitto on
// loopback throughout.
//  1. Command latency: a simulated device and its `serve --mqtt`; pen down and up commands
//     published on the machine's command topic, timed to the reply (ctl has seen the device
//     change) and to the retained status that shows it (what a watcher sees, 10 reads a second).
//  2. Traffic while drawing: every message under pathstream/ while the machine draws a job
//     from its jobs topic, per second and in bytes, and serve's own CPU time at rest.
//  3. Capacity: N simulated machines (one MQTT connection each, as serve has) publishing a
//     status and an event of serve's size 10 times a second, one watcher of every status;
//     per N the broker's CPU, the publishers', what reached the watcher and how late.
// The baseline every capacity ratio is relative to is the first N. Exit 1 when a command is
// not answered or the watcher misses statuses at the smallest N, 2 on a usage error; wall
// times and rates are printed, never judged.
//   build/dev/bench/bench_mqtt [--quick] [--markdown]
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_args.hpp"
#include "mosquitto_broker.hpp"
#include "pathstream/host/mqtt_client.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using pathstream::host::MqttClient;
using pathstream::host::parse_mqtt_url;
namespace fs = std::filesystem;

const char* const kUsage =
    "usage: bench_mqtt [--quick] [--markdown] [--help]\n"
    "  Command latency through the broker to a simulated device, the traffic of a machine\n"
    "  drawing, and how many simulated machines at 10 status messages a second one broker\n"
    "  carries on this machine. --quick: 5 commands and 10 machines for 1 s (the ctest smoke "
    "run).\n"
    "exit: 0, 1 when a command is not answered or statuses are lost at the smallest N, 2 usage\n";

double now_s() {
    return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
}

// CPU seconds a process has used (utime + stime, /proc/PID/stat).
double cpu_seconds(pid_t pid) {
    std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t close = text.rfind(')');
    if (close == std::string::npos) return 0;
    std::istringstream fields(text.substr(close + 2));
    std::string skip;
    for (int i = 0; i < 11; ++i) fields >> skip;  // state .. cmajflt
    double utime = 0, stime = 0;
    fields >> utime >> stime;
    return (utime + stime) / static_cast<double>(sysconf(_SC_CLK_TCK));
}

/// A child process of this bench, killed at the end.
struct Child {
    pid_t pid = -1;
    Child(const std::vector<std::string>& args, const std::string& log) {
        std::vector<char*> argv;
        for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
        argv.push_back(nullptr);
        posix_spawn_file_actions_t actions;
        posix_spawn_file_actions_init(&actions);
        posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                         0644);
        posix_spawn_file_actions_adddup2(&actions, 1, 2);
        if (posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ) != 0) pid = -1;
        posix_spawn_file_actions_destroy(&actions);
    }
    ~Child() {
        if (pid <= 0) return;
        kill(pid, SIGINT);
        for (int i = 0; i < 100 && waitpid(pid, nullptr, WNOHANG) == 0; ++i)
            std::this_thread::sleep_for(std::chrono::milliseconds(50));
        kill(pid, SIGKILL);
        waitpid(pid, nullptr, 0);
    }
};

// Waits (up to 10 s) for `pattern` in a log and returns the word it starts.
std::string wait_for_word(const std::string& log, const std::string& pattern) {
    for (int i = 0; i < 200; ++i) {
        std::ifstream in(log);
        std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        const std::size_t at = text.find(pattern);
        if (at != std::string::npos) return text.substr(at, text.find_first_of(" \n", at) - at);
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return "";
}

/// Messages seen by a subscriber, by topic, with arrival times.
struct Inbox {
    std::mutex mutex;
    std::condition_variable changed;
    std::vector<std::pair<std::string, std::string>> messages;
    std::vector<double> at;
    void add(const std::string& t, const std::string& p) {
        {
            const std::lock_guard lock(mutex);
            messages.emplace_back(t, p);
            at.push_back(now_s());
        }
        changed.notify_all();
    }
    /// Waits (up to `timeout_s`) for a message after index `from` that `match` accepts; its
    /// arrival time, or a negative value.
    template <typename Match>
    double wait(std::size_t from, double timeout_s, Match&& match) {
        std::unique_lock lock(mutex);
        const auto deadline = Clock::now() + std::chrono::duration<double>(timeout_s);
        for (std::size_t i = from;;) {
            for (; i < messages.size(); ++i)
                if (match(messages[i].first, messages[i].second)) return at[i];
            if (changed.wait_until(lock, deadline) == std::cv_status::timeout) return -1;
        }
    }
    std::size_t size() {
        const std::lock_guard lock(mutex);
        return messages.size();
    }
};

double percentile(std::vector<double> v, double p) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[std::min(v.size() - 1, static_cast<std::size_t>(p * static_cast<double>(v.size())))];
}

}  // namespace

int main(int argc, char** argv) {
    pathstream::bench::BenchArgs args;
    if (const auto status = pathstream::bench::parse_bench_args(argc, argv, kUsage, args))
        return *status;
    rlimit files{};
    getrlimit(RLIMIT_NOFILE, &files);
    files.rlim_cur = files.rlim_max;
    setrlimit(RLIMIT_NOFILE, &files);
    signal(SIGPIPE, SIG_IGN);
    pathstream::test::MosquittoBroker broker;
    const std::string url = broker.url();
    const fs::path work = fs::temp_directory_path() / ("bench-mqtt-" + std::to_string(getpid()));
    fs::create_directories(work);
    const std::string machine =
        std::string(PATHSTREAM_SOURCE_DIR) + "/examples/machines/pen_plotter.json";
    int failures = 0;

    // 1. Command latency.
    Child device({PATHSTREAM_CLI, "device", "-m", machine, "--no-gpio", "--tcp", "127.0.0.1:0",
                  "--exit-after", "600"},
                 (work / "device.log").string());
    const std::string target = wait_for_word((work / "device.log").string(), "modbus-tcp://");
    Child serve({PATHSTREAM_CLI, "serve", "-m", machine, "-t", target, "--listen", "127.0.0.1:0",
                 "--state-dir", (work / "state").string(), "--mqtt", url, "--name", "bench-1"},
                (work / "serve.log").string());
    Inbox inbox;
    MqttClient watcher(parse_mqtt_url(url), "bench-watcher", {},
                       [&](const std::string& t, const std::string& p) { inbox.add(t, p); });
    watcher.connect();
    watcher.subscribe("pathstream/#", 0);
    if (inbox.wait(0, 10, [](const std::string& t, const std::string& p) {
            return t == "pathstream/bench-1/online" &&
                   p.find("\"online\":true") != std::string::npos;
        }) < 0) {
        std::fprintf(stderr, "bench_mqtt: serve did not come online (%s)\n",
                     (work / "serve.log").c_str());
        return 1;
    }
    const int commands = args.quick ? 5 : 20;
    std::vector<double> to_reply, to_status;
    for (int i = 0; i < commands; ++i) {
        const bool down = i % 2 == 0;
        const std::string id = "c" + std::to_string(i);
        const std::size_t from = inbox.size();
        const double t0 = now_s();
        watcher.publish("pathstream/bench-1/command",
                        nlohmann::json{{"id", id}, {"verb", "pen"}, {"down", down}}.dump(), 1);
        const double reply = inbox.wait(from, 20, [&](const std::string& t, const std::string& p) {
            return t == "pathstream/bench-1/reply" && p.find("\"" + id + "\"") != std::string::npos;
        });
        const std::string want = std::string("\"pen_down\":") + (down ? "true" : "false");
        const double status = inbox.wait(from, 20, [&](const std::string& t, const std::string& p) {
            return t == "pathstream/bench-1/status" && p.find(want) != std::string::npos;
        });
        if (reply < 0 || status < 0) {
            ++failures;
            continue;
        }
        to_reply.push_back(1000 * (reply - t0));
        to_status.push_back(1000 * (status - t0));
    }
    std::printf(
        "command latency (pen down/up, %d commands, ms): reply median %.1f p95 %.1f max %.1f; "
        "status median %.1f p95 %.1f max %.1f\n",
        commands, percentile(to_reply, 0.5), percentile(to_reply, 0.95), percentile(to_reply, 1.0),
        percentile(to_status, 0.5), percentile(to_status, 0.95), percentile(to_status, 1.0));

    // 2. Serve at rest, then the traffic of one machine drawing.
    const double idle_s = args.quick ? 1 : 10;
    const double c0 = cpu_seconds(serve.pid);
    std::this_thread::sleep_for(std::chrono::duration<double>(idle_s));
    const double serve_idle = (cpu_seconds(serve.pid) - c0) / idle_s;
    std::printf(
        "serve at rest (10 device reads and status messages a second): %.2f %% of a core "
        "-> %.0f machines per host core\n",
        100 * serve_idle, serve_idle > 0 ? 1 / serve_idle : 0);
    std::ifstream drawing_in(std::string(PATHSTREAM_SOURCE_DIR) + "/examples/rose.json");
    const std::string drawing((std::istreambuf_iterator<char>(drawing_in)),
                              std::istreambuf_iterator<char>());
    const std::size_t job_from = inbox.size();
    watcher.publish(
        "pathstream/bench-1/jobs",
        nlohmann::json{{"id", "bench-rose"}, {"file", "rose.json"}, {"drawing", drawing}}.dump(),
        1);
    const double started = inbox.wait(job_from, 30, [](const std::string& t, const std::string& p) {
        return t == "pathstream/jobs/bench-rose/state" &&
               p.find("\"running\"") != std::string::npos;
    });
    const double window_s = args.quick ? 1.5 : 10;
    std::this_thread::sleep_for(std::chrono::duration<double>(window_s));
    std::map<std::string, std::pair<std::size_t, std::size_t>> per_leaf;
    std::size_t messages = 0, bytes = 0;
    {
        const std::lock_guard lock(inbox.mutex);
        for (std::size_t i = job_from; i < inbox.messages.size(); ++i) {
            if (started < 0 || inbox.at[i] < started || inbox.at[i] > started + window_s) continue;
            const auto& [t, p] = inbox.messages[i];
            const std::string leaf = t.substr(t.rfind('/') + 1);
            per_leaf[leaf].first++;
            per_leaf[leaf].second += t.size() + p.size();
            ++messages;
            bytes += t.size() + p.size();
        }
    }
    std::printf("drawing rose.json: %.1f messages/s, %.0f B/s (topic + payload) over %.0f s:",
                static_cast<double>(messages) / window_s, static_cast<double>(bytes) / window_s,
                window_s);
    for (const auto& [leaf, c] : per_leaf)
        std::printf(" %s %.1f/s %.0f B/s;", leaf.c_str(), static_cast<double>(c.first) / window_s,
                    static_cast<double>(c.second) / window_s);
    std::printf("\n");
    if (started < 0) ++failures;

    // 3. Capacity at 10 Hz.
    std::string status_payload;
    {
        const std::lock_guard lock(inbox.mutex);
        for (const auto& [t, p] : inbox.messages)
            if (t == "pathstream/bench-1/status") status_payload = p;
    }
    std::printf(
        "\n%s\n",
        args.markdown
            ? "| machines | broker CPU | publishers' CPU | statuses delivered | latency p50 | "
              "latency p95 | broker CPU per machine |\n|---:|---:|---:|---:|---:|---:|---:|"
            : "machines  broker CPU  publishers CPU  delivered  p50 ms  p95 ms  broker "
              "CPU/machine");
    std::vector<int> counts =
        args.quick ? std::vector<int>{10} : std::vector<int>{10, 100, 250, 500, 1000, 2000, 3000};
    double baseline_per_machine = 0;
    for (const int n : counts) {
        std::vector<double> latency;
        std::size_t delivered = 0;
        std::set<std::string> seen;
        std::mutex latency_mutex;
        // Retained statuses of the last round arrive at once on subscribing: not counted.
        const double round_start = now_s();
        MqttClient fleet(parse_mqtt_url(url), "bench-fleet", {},
                         [&](const std::string&, const std::string& p) {
                             const std::size_t at = p.find("\"sent\":");
                             if (at == std::string::npos) return;
                             const double sent = std::stod(p.substr(at + 7));
                             if (sent < round_start) return;
                             const double late = 1000 * (now_s() - sent);
                             const std::lock_guard lock(latency_mutex);
                             // A status the broker sends again counts once.
                             if (!seen.insert(p).second) return;
                             ++delivered;
                             latency.push_back(late);
                         });
        fleet.connect();
        fleet.subscribe("pathstream/+/status", 0);
        // libmosquitto waits on select(): one process serves at most about 300 connections
        // (three descriptors each under FD_SETSIZE), so the simulated machines are spread over
        // child processes of at most 200. They start together at `start`, on the monotonic
        // clock every process shares.
        const double run_s = args.quick ? 1 : 5;
        const int per_process = 200;
        const auto start = Clock::now() + std::chrono::milliseconds(2000 + 10 * n);
        std::vector<pid_t> children;
        for (int first = 0; first < n; first += per_process) {
            const int last = std::min(n, first + per_process);
            const pid_t pid = fork();
            if (pid == 0) {
                std::vector<std::unique_ptr<MqttClient>> machines;
                try {
                    for (int k = first; k < last; ++k) {
                        machines.push_back(std::make_unique<MqttClient>(
                            parse_mqtt_url(url), "sim-" + std::to_string(k)));
                        machines.back()->connect(std::chrono::seconds(20));
                    }
                    std::this_thread::sleep_until(start);
                    for (int tick = 0; tick < static_cast<int>(run_s * 10); ++tick) {
                        for (int k = first; k < last; ++k) {
                            char stamp[48];
                            std::snprintf(stamp, sizeof stamp, ",\"sent\":%.6f}", now_s());
                            const std::string payload =
                                status_payload.substr(0, status_payload.size() - 1) + stamp;
                            const std::string base = "pathstream/sim-" + std::to_string(k) + "/";
                            MqttClient& m = *machines[static_cast<std::size_t>(k - first)];
                            m.publish(base + "status", payload, 0, true);
                            m.publish(base + "events", payload, 0, false);
                        }
                        std::this_thread::sleep_until(start +
                                                      std::chrono::milliseconds(100 * (tick + 1)));
                    }
                    std::this_thread::sleep_for(std::chrono::milliseconds(300));
                    for (auto& m : machines) m->disconnect();
                } catch (const std::exception& e) {
                    std::fprintf(stderr, "bench_mqtt: simulated machines %d..%d: %s\n", first,
                                 last - 1, e.what());
                    _exit(1);
                }
                _exit(0);
            }
            children.push_back(pid);
        }
        const std::size_t sent = static_cast<std::size_t>(n) * static_cast<std::size_t>(run_s * 10);
        std::this_thread::sleep_until(start);
        double p0 = 0, p1 = 0;
        const double b0 = cpu_seconds(broker.pid());
        for (const pid_t c : children) p0 += cpu_seconds(c);
        std::this_thread::sleep_until(start + std::chrono::duration<double>(run_s));
        for (const pid_t c : children) p1 += cpu_seconds(c);
        const double b1 = cpu_seconds(broker.pid());
        bool children_ok = true;
        for (const pid_t c : children) {
            int status = 0;
            waitpid(c, &status, 0);
            children_ok = children_ok && WIFEXITED(status) && WEXITSTATUS(status) == 0;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        fleet.disconnect();
        if (!children_ok) {
            std::printf("stopped at %d machines: simulated machines could not connect\n", n);
            if (n == counts.front()) ++failures;
            break;
        }
        const double broker_cpu = (b1 - b0) / run_s;
        const double publisher_cpu = (p1 - p0) / run_s;
        double fraction = 0, p50 = 0, p95 = 0;
        {
            const std::lock_guard lock(latency_mutex);
            fraction = static_cast<double>(delivered) / static_cast<double>(sent);
            p50 = percentile(latency, 0.5);
            p95 = percentile(latency, 0.95);
        }
        const double per_machine = broker_cpu / n;
        if (baseline_per_machine == 0) baseline_per_machine = per_machine;
        std::printf(
            args.markdown ? "| %d | %.1f %% | %.1f %% | %.2f %% | %.1f ms | %.1f ms | %.4f %% "
                            "(%.2fx the %d-machine figure) |\n"
                          : "%8d  %9.1f%%  %13.1f%%  %8.2f%%  %6.1f  %6.1f  %.4f%% (%.2fx "
                            "the %d-machine figure)\n",
            n, 100 * broker_cpu, 100 * publisher_cpu, 100 * fraction, p50, p95, 100 * per_machine,
            baseline_per_machine > 0 ? per_machine / baseline_per_machine : 0, counts.front());
        std::fflush(stdout);
        if (n == counts.front() && fraction < 0.99) ++failures;
        if (fraction < 0.9 || p95 > 1000) {
            std::printf(
                "stopped at %d machines: the watcher got %.1f %% of the statuses, p95 %.0f "
                "ms\n",
                n, 100 * fraction, p95);
            break;
        }
    }
    std::error_code ignored;
    fs::remove_all(work, ignored);
    return failures == 0 ? 0 : 1;
}
