// The fleet's view of the broker and its job messages: folding, hostile payloads, caps, ids.
#include <catch2/catch.hpp>
#include <random>
#include <string>

#include "pathstream/host/fleet_job.hpp"
#include "pathstream/host/fleet_view.hpp"

using namespace pathstream::host;

namespace {

const char* kOnline =
    R"({"name":"p1","machine":"pen_plotter.json","axes":["x","y"],"target":"t","online":true})";
const char* kStatus =
    R"({"event":"device","state":"running","pen_down":true,"position_mm":{"x":12.5,"y":-3}})";

std::string job_state(const std::string& id, const std::string& state, const std::string& machine,
                      double at) {
    return R"({"id":")" + id + R"(","state":")" + state + R"(","machine":)" +
           (machine.empty() ? "null" : "\"" + machine + "\"") + R"(,"file":"rose.json","at":)" +
           std::to_string(at) +
           R"(,"error":"","history":[{"state":"queued","machine":null,"at":1}]})";
}

}  // namespace

TEST_CASE("fleet view: a machine from its online, status and progress topics", "[fleet]") {
    FleetView v;
    CHECK(v.apply("pathstream/p1/online", kOnline));
    CHECK(v.apply("pathstream/p1/status", kStatus));
    CHECK(v.apply("pathstream/p1/progress", R"({"event":"progress","fraction":0.25,"eta_s":12})"));
    const auto ms = v.machines();
    REQUIRE(ms.size() == 1);
    CHECK(ms[0].name == "p1");
    CHECK(ms[0].online);
    CHECK(ms[0].machine_file == "pen_plotter.json");
    CHECK(ms[0].axes == std::vector<std::string>{"x", "y"});
    CHECK(ms[0].state == "running");
    CHECK(ms[0].position_mm.at("x") == 12.5);
    CHECK(ms[0].fraction == 0.25);
    CHECK(ms[0].eta_s == 12);
    CHECK(v.ignored() == 0);
    // The will: offline, the rest kept.
    CHECK(v.apply("pathstream/p1/online", R"({"name":"p1","online":false})"));
    CHECK_FALSE(v.machines()[0].online);
    CHECK(v.machines()[0].machine_file == "pen_plotter.json");
    // A retained message cleared forgets the machine.
    CHECK(v.apply("pathstream/p1/online", ""));
    CHECK(v.machines().empty());
}

TEST_CASE("fleet view: jobs, their history and the machine's current job", "[fleet]") {
    FleetView v;
    v.apply("pathstream/p1/online", kOnline);
    CHECK(v.apply("pathstream/jobs/a/state", job_state("a", "queued", "", 10)));
    CHECK(v.apply("pathstream/jobs/b/state", job_state("b", "done", "p1", 20)));
    CHECK(v.machines()[0].job.empty());
    CHECK(v.apply("pathstream/jobs/a/state", job_state("a", "running", "p1", 30)));
    CHECK(v.apply("pathstream/jobs/a/progress", R"({"fraction":0.5,"eta_s":3})"));
    CHECK(v.machines()[0].job == "a");
    const auto js = v.jobs();
    REQUIRE(js.size() == 2);
    CHECK(js[0].id == "a");  // newest first
    CHECK(js[0].fraction == 0.5);
    CHECK(js[0].history.size() == 1);
    CHECK(js[0].history[0].state == "queued");
    CHECK(js[0].history[0].machine.empty());
    CHECK(v.apply("pathstream/jobs/a/state", job_state("a", "interrupted", "p1", 40)));
    CHECK(v.machines()[0].job == "a");  // an interrupted job stays on its machine
    CHECK(v.apply("pathstream/jobs/a/state", job_state("a", "dropped", "p1", 50)));
    CHECK(v.machines()[0].job.empty());
    const auto j = v.to_json();
    CHECK(j["jobs"][0]["id"] == "a");
    CHECK(j["machines"][0]["job"].is_null());
    CHECK(j["machines"][0]["fraction"].is_null());
}

TEST_CASE("fleet view: hostile payloads are counted and change nothing", "[fleet]") {
    FleetView v;
    v.apply("pathstream/p1/online", kOnline);
    v.apply("pathstream/jobs/a/state", job_state("a", "running", "p1", 1));
    // Everything but the count of ignored messages.
    auto described = [&v] {
        nlohmann::json j = v.to_json();
        j.erase("ignored");
        return j.dump();
    };
    const std::string before = described();
    const std::string huge(kFleetMaxPayload + 1, ' ');
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    const std::pair<const char*, std::string> bad[] = {
        {"pathstream/p1/online", "not json"},
        {"pathstream/p1/online", "[1,2]"},
        {"pathstream/p1/online", R"({"online":"yes"})"},
        {"pathstream/p1/online", R"({"online":true,"axes":"xy"})"},
        {"pathstream/p1/online", R"({"online":true,"axes":[1]})"},
        {"pathstream/p1/status", R"({"state":7})"},
        {"pathstream/p1/status", R"({"state":"idle","position_mm":{"x":"far"}})"},
        {"pathstream/p1/progress", R"({"fraction":"half"})"},
        {"pathstream/p1/online", huge},
        {"pathstream/p1/online", deep},
        {"pathstream/jobs/a/state", R"({"state":"exploded"})"},
        {"pathstream/jobs/a/state", R"({"id":"b","state":"done"})"},
        {"pathstream/jobs/a/state", R"({"state":"done","history":[{"state":1}]})"},
        {"pathstream/jobs/a/state", R"({"state":"done","at":"noon"})"},
        {"pathstream/jobs/a/progress", "{"},
        {"pathstream/bad name/online", kOnline},
        {"pathstream/jobs/bad+id/state", job_state("bad+id", "done", "", 1)},
    };
    for (const auto& [topic, payload] : bad) {
        INFO(topic << " " << payload.substr(0, 60));
        CHECK_FALSE(v.apply(topic, payload));
    }
    CHECK(v.ignored() == std::size(bad));
    CHECK(described() == before);
    // Topics the view does not describe are neither folded nor counted.
    CHECK_FALSE(v.apply("pathstream/p1/command", "x"));
    CHECK_FALSE(v.apply("pathstream/queue/any", "x"));
    CHECK_FALSE(v.apply("pathstream/queue/online", kOnline));  // a queue named like a leaf
    CHECK_FALSE(v.apply("elsewhere/p1/online", kOnline));
    CHECK(v.ignored() == std::size(bad));
}

TEST_CASE("fleet view: machines and jobs are capped", "[fleet]") {
    FleetView v;
    for (std::size_t i = 0; i < kFleetMaxMachines + 10; ++i)
        v.apply("pathstream/m" + std::to_string(i) + "/online", R"({"online":true})");
    CHECK(v.machines().size() == kFleetMaxMachines);
    CHECK(v.ignored() == 10);
    // Jobs: the oldest finished one makes room for a new one.
    FleetView w;
    for (std::size_t i = 0; i < kFleetMaxJobs; ++i) {
        const std::string id = "j" + std::to_string(i);
        w.apply("pathstream/jobs/" + id + "/state",
                job_state(id, i == 5 ? "done" : "running", "p", 100.0 + double(i)));
    }
    CHECK(w.apply("pathstream/jobs/new/state", job_state("new", "queued", "", 1e6)));
    CHECK(w.jobs().size() == kFleetMaxJobs);
    CHECK(w.job("j5") == nullptr);
    CHECK(w.job("new") != nullptr);
    // Every job active: the next one has no room.
    CHECK_FALSE(w.apply("pathstream/jobs/newer/state", job_state("newer", "queued", "", 2e6)));
}

TEST_CASE("fleet job: the message and its queued state", "[fleet]") {
    std::mt19937_64 random(7);
    FleetJobSpec s;
    s.file_name = "/home/ann/rose.json";
    s.drawing = "{\"type\":\"path\"}";
    s.options = {{"fit", "a4"}, {"margin", 10}};
    const FleetJobMessages q = build_fleet_job(s, 1795990489.5, random);
    CHECK(q.topic == "pathstream/queue/any");
    CHECK(q.state_topic == "pathstream/jobs/" + q.id + "/state");
    CHECK(q.id.rfind("job-20261129-221449-", 0) == 0);
    CHECK(q.id.size() == std::string("job-20261129-213449-abcd").size());
    CHECK(q.message["file"] == "rose.json");
    CHECK(q.message["drawing"] == s.drawing);
    CHECK(q.message["options"]["fit"] == "a4");
    CHECK(q.message["kind"] == "any");
    CHECK(q.state["state"] == "queued");
    CHECK(q.state["machine"].is_null());
    CHECK(q.state["history"].size() == 1);
    // The state as the view reads it.
    FleetView v;
    CHECK(v.apply(q.state_topic, q.state.dump()));
    CHECK(v.job(q.id)->state == "queued");

    s.id = "print-0007";
    s.machine = "plotter-2";
    const FleetJobMessages m = build_fleet_job(s, 0, random);
    CHECK(m.id == "print-0007");
    CHECK(m.topic == "pathstream/plotter-2/jobs");
    CHECK(m.message["machine"] == "plotter-2");
    s.machine.clear();
    s.kind = "pen_plotter";
    CHECK(build_fleet_job(s, 0, random).topic == "pathstream/queue/pen_plotter");
    for (const char* ext : {"a.csv", "a.svg", "a.ngc", "a.gcode", "a.nc", "a.bpt"}) {
        s.file_name = ext;
        CHECK_NOTHROW(build_fleet_job(s, 0, random));
    }
}

TEST_CASE("fleet job: bad submissions say why", "[fleet]") {
    std::mt19937_64 random(1);
    FleetJobSpec s;
    s.file_name = "rose.json";
    s.drawing = "{}";
    auto refused = [&](FleetJobSpec bad, const std::string& words) {
        INFO(words);
        CHECK_THROWS_WITH(build_fleet_job(bad, 0, random), Catch::Contains(words));
    };
    FleetJobSpec b = s;
    b.id = "a/b";
    refused(b, "1 to 64 of A-Z a-z 0-9 _ -");
    b.id = std::string(65, 'a');
    refused(b, "1 to 64");
    b = s;
    b.file_name = "rose.docx";
    refused(b, "no reader knows its extension (.json");
    // As the machines check it: lower case, and no .gc (a machine would refuse the job).
    b.file_name = "rose.SVG";
    refused(b, "no reader knows its extension");
    b.file_name = "rose.gc";
    refused(b, "no reader knows its extension");
    b.file_name = ".json";
    refused(b, "no leading .");
    b = s;
    b.drawing.assign(b.max_bytes + 1, 'x');
    refused(b, "a job may carry");
    b = s;
    b.drawing = "\xff\xfe";
    refused(b, "not UTF-8");
    b = s;
    b.kind = "k";
    b.machine = "m";
    refused(b, "not both");
    b = s;
    b.kind = "#";
    refused(b, "kind \"#\"");
    b = s;
    b.options = 3;
    refused(b, "options must be an object");
    // Generated ids differ.
    s.id.clear();
    CHECK(build_fleet_job(s, 0, random).id != build_fleet_job(s, 0, random).id);
    CHECK(generate_job_id(0, random).rfind("job-19700101-000000-", 0) == 0);
}
