// The machine's job desk with its server and broker replaced by recording hooks: which jobs it
// takes, which it passes back or refuses, what it publishes, and what a host that died leaves
// for the next start. The real broker's side is tests/cli/mqtt_jobs_test.sh.
#include <atomic>
#include <catch2/catch.hpp>
#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <fstream>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "serve/job_desk.hpp"

using namespace pathstream::host::serve;
namespace fs = std::filesystem;

namespace {

struct Published {
    std::string topic, payload;
    bool retain;
};

/// The hooks a desk runs with, recording what it does.
struct Fake {
    std::mutex mutex;
    std::condition_variable changed;
    std::vector<Published> published;
    std::vector<std::string> started;
    std::atomic<bool> busy{false};
    int start_status = 200;
    std::function<void()> during_start;  ///< runs inside the start hook

    JobDeskHooks hooks() {
        JobDeskHooks h;
        h.start = [this](const JobMessage& j) {
            const std::lock_guard lock(mutex);
            started.push_back(j.id);
            if (during_start) during_start();
            return std::make_pair(start_status, nlohmann::json{{"error", "no such pen"}});
        };
        h.resume = [] { return std::make_pair(200, nlohmann::json{{"ok", true}}); };
        h.busy = [this] { return busy.load(); };
        h.publish = [this](const std::string& t, const std::string& p, int, bool retain) {
            {
                const std::lock_guard lock(mutex);
                published.push_back({t, p, retain});
            }
            changed.notify_all();
        };
        return h;
    }
    /// Waits (up to 10 s) until `count` messages are published; returns them.
    std::vector<Published> wait_for(std::size_t count) {
        std::unique_lock lock(mutex);
        changed.wait_for(lock, std::chrono::seconds(10), [&] { return published.size() >= count; });
        return published;
    }
};

std::string job(const std::string& id, unsigned bounces = 0) {
    return nlohmann::json{{"id", id},
                          {"file", "a.csv"},
                          {"drawing", "0,0\n1,1\n"},
                          {"bounces", bounces},
                          {"submitted", 1.0}}
        .dump();
}

nlohmann::json state_of(const Published& p) {
    return nlohmann::json::parse(p.payload);
}

struct TempDir {
    fs::path path;
    TempDir() {
        path = fs::temp_directory_path() /
               ("pathstream-desk-" +
                std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
        fs::create_directories(path);
    }
    ~TempDir() {
        std::error_code ignored;
        fs::remove_all(path, ignored);
    }
};

}  // namespace

TEST_CASE("the desk takes a free machine's job once and reports its states",
          "[mqtt][jobs][threads]") {
    TempDir dir;
    Fake fake;
    JobDesk desk("m1", "pen_plotter", dir.path.string(), 1000, fake.hooks());
    CHECK(desk.filters() == std::vector<std::string>{
                                "pathstream/m1/jobs", "$share/pathstream-any/pathstream/queue/any",
                                "$share/pathstream-pen_plotter/pathstream/queue/pen_plotter"});
    desk.start();
    desk.on_message("pathstream/queue/pen_plotter", job("j1"));
    auto p = fake.wait_for(1);
    REQUIRE(p.size() == 1);
    CHECK(p[0].topic == "pathstream/jobs/j1/state");
    CHECK(p[0].retain);
    CHECK(state_of(p[0])["state"] == "running");
    CHECK(state_of(p[0])["machine"] == "m1");
    CHECK(state_of(p[0])["history"].size() == 2);  // queued (submitted), running
    CHECK(desk.current() == "j1");
    CHECK(fs::exists(dir.path / "mqtt_job.json"));
    // The same job delivered again (QoS 1) is not taken twice.
    fake.busy = true;
    desk.on_message("pathstream/queue/pen_plotter", job("j1"));
    desk.job_ended("finished", 0, "");
    p = fake.wait_for(2);
    REQUIRE(p.size() == 2);
    CHECK(state_of(p[1])["state"] == "done");
    CHECK(desk.current().empty());
    CHECK(!fs::exists(dir.path / "mqtt_job.json"));
    CHECK(fake.started == std::vector<std::string>{"j1"});
}

TEST_CASE("a busy desk passes queued jobs back and refuses its own", "[mqtt][jobs][threads]") {
    TempDir dir;
    Fake fake;
    fake.busy = true;  // a job from the page runs
    JobDesk desk("m1", "pen_plotter", dir.path.string(), 1000, fake.hooks());
    desk.start();
    desk.on_message("pathstream/queue/any", job("q1", 2));
    desk.on_message("pathstream/m1/jobs", job("d1"));
    const auto p = fake.wait_for(2);
    REQUIRE(p.size() == 2);
    CHECK(p[0].topic == "pathstream/queue/any");
    CHECK(!p[0].retain);
    CHECK(nlohmann::json::parse(p[0].payload)["bounces"] == 3);
    CHECK(p[1].topic == "pathstream/jobs/d1/state");
    CHECK(state_of(p[1])["state"] == "refused");
    CHECK(desk.passed_back() == 1);
    CHECK(fake.started.empty());
    // Nothing is left in the inbox once handled.
    desk.stop();
    CHECK(fs::is_empty(dir.path / "mqtt_inbox"));
}

TEST_CASE("a job that cannot start fails with the server's reason", "[mqtt][jobs][threads]") {
    TempDir dir;
    Fake fake;
    fake.start_status = 422;
    JobDesk desk("m1", "any", dir.path.string(), 1000, fake.hooks());
    desk.start();
    desk.on_message("pathstream/queue/any", job("j1"));
    desk.on_message("pathstream/queue/any", R"({"id": "bad", "file": "x.exe", "drawing": ""})");
    const auto p = fake.wait_for(2);
    REQUIRE(p.size() == 2);
    CHECK(state_of(p[0])["state"] == "failed");
    CHECK(state_of(p[0])["error"] == "no such pen");
    CHECK(state_of(p[1])["id"] == "bad");
    CHECK(state_of(p[1])["state"] == "failed");
    CHECK(desk.current().empty());
    CHECK(desk.dropped() == 1);
}

TEST_CASE("a host that died: its job is interrupted, its unread jobs are read",
          "[mqtt][jobs][threads]") {
    TempDir dir;
    {
        std::ofstream(dir.path / "mqtt_job.json")
            << R"({"id": "j0", "state": "running", "machine": "m1", "file": "a.csv", "at": 1,
                  "error": "", "history": [{"state": "running", "machine": "m1", "at": 1}]})";
        fs::create_directories(dir.path / "mqtt_inbox");
        std::ofstream(dir.path / "mqtt_inbox" / "7.msg") << "pathstream/queue/any\n" << job("j2");
    }
    Fake fake;
    JobDesk desk("m1", "any", dir.path.string(), 1000, fake.hooks());
    desk.start();
    const auto p = fake.wait_for(2);
    REQUIRE(p.size() == 2);
    CHECK(state_of(p[0])["id"] == "j0");
    CHECK(state_of(p[0])["state"] == "interrupted");
    CHECK(desk.current() == "j0");
    // The machine still has j0: the job it had received goes back to the queue.
    CHECK(p[1].topic == "pathstream/queue/any");
    CHECK(nlohmann::json::parse(p[1].payload)["id"] == "j2");
    // The operator resumes j0 there; it ends; the machine is free.
    const auto [status, body] = desk.resume_job();
    CHECK(status == 200);
    desk.job_ended("finished", 0, "");
    const auto q = fake.wait_for(4);
    REQUIRE(q.size() == 4);
    CHECK(state_of(q[2])["state"] == "running");
    CHECK(state_of(q[3])["state"] == "done");
    std::vector<std::string> states;
    const nlohmann::json done = state_of(q[3]);
    for (const auto& h : done["history"]) states.push_back(h["state"]);
    CHECK(states == std::vector<std::string>{"running", "interrupted", "running", "done"});
    CHECK(desk.resume_job().first == 409);
    CHECK(desk.drop_job().first == 409);
}

TEST_CASE("a stream that ends before its start is answered still ends the job",
          "[mqtt][jobs][threads]") {
    TempDir dir;
    Fake fake;
    JobDesk desk("m1", "any", dir.path.string(), 1000, fake.hooks());
    // The server's job thread reports the end while the desk still waits for the start's
    // answer (a stream that fails at once).
    fake.during_start = [&] {
        std::thread([&] { desk.job_ended("failed", 6, "device: no answer"); }).join();
    };
    desk.start();
    desk.on_message("pathstream/queue/any", job("j1"));
    const auto p = fake.wait_for(2);
    REQUIRE(p.size() == 2);
    CHECK(state_of(p[0])["state"] == "running");
    CHECK(state_of(p[1])["state"] == "failed");
    CHECK(state_of(p[1])["error"] == "device: no answer");
    CHECK(desk.current().empty());
}
