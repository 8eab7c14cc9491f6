// `pathstream serve`'s parts that need no browser: who may use it (token, Host, Origin), what
// the page may ask for (upload names, path options as arguments), the preview of a plan, the
// event hub under two real threads and a seeded interleaving, and the child process runner.
#include <algorithm>
#include <catch2/catch.hpp>
#include <random>
#include <thread>

#include "pathstream/host/geometry.hpp"
#include "pathstream/host/planner.hpp"
#include "serve/access.hpp"
#include "serve/child_process.hpp"
#include "serve/drawing_request.hpp"
#include "serve/event_hub.hpp"
#include "serve/preview.hpp"

using namespace pathstream::host;
using namespace pathstream::host::serve;

namespace {

RequestFacts get(const std::string& host, const std::string& origin = "") {
    RequestFacts r;
    r.method = "GET";
    r.host = host;
    r.origin = origin;
    return r;
}

}  // namespace

TEST_CASE("serve: loopback hosts", "[serve]") {
    CHECK(is_loopback_host("127.0.0.1"));
    CHECK(is_loopback_host("127.255.0.9"));
    CHECK(is_loopback_host("::1"));
    CHECK(is_loopback_host("[::1]"));
    CHECK(is_loopback_host("localhost"));
    CHECK_FALSE(is_loopback_host("0.0.0.0"));
    CHECK_FALSE(is_loopback_host("127.0.0.1.evil.example"));
    CHECK_FALSE(is_loopback_host("127.0.0.256"));
    CHECK_FALSE(is_loopback_host("192.168.1.2"));
    CHECK_FALSE(is_loopback_host(""));
}

TEST_CASE("serve: listen addresses", "[serve]") {
    CHECK(parse_listen_address("127.0.0.1:8080").host == "127.0.0.1");
    CHECK(parse_listen_address("127.0.0.1:8080").port == 8080);
    CHECK(parse_listen_address("[::1]:0").host == "::1");
    CHECK_THROWS_AS(parse_listen_address("127.0.0.1"), std::invalid_argument);
    CHECK_THROWS_AS(parse_listen_address("127.0.0.1:http"), std::invalid_argument);
    CHECK_THROWS_AS(parse_listen_address("127.0.0.1:70000"), std::invalid_argument);
}

TEST_CASE("serve: on loopback, the Host and Origin must be this server's", "[serve]") {
    AccessPolicy p;
    p.port = 8080;
    CHECK_FALSE(refusal(p, get("127.0.0.1:8080")));
    CHECK_FALSE(refusal(p, get("localhost:8080", "http://localhost:8080")));
    // A page elsewhere that rebinds its own name to 127.0.0.1 sends that name as the Host.
    CHECK(refusal(p, get("evil.example:8080")));
    CHECK(refusal(p, get("127.0.0.1:9999")));
    CHECK(refusal(p, get("127.0.0.1:8080", "http://evil.example")));
    RequestFacts post = get("127.0.0.1:8080");
    post.method = "POST";
    CHECK(refusal(p, post));  // no Origin: not from the page
    post.origin = "http://127.0.0.1:8080";
    CHECK_FALSE(refusal(p, post));
}

TEST_CASE("serve: beyond loopback every request carries the token", "[serve]") {
    AccessPolicy p;
    p.loopback = false;
    p.port = 8080;
    p.token = "s3cret-token";
    RequestFacts r = get("plotter.local:8080");
    CHECK(refusal(p, r).value() == "missing or wrong token");
    r.query_token = "s3cret-tokeN";
    CHECK(refusal(p, r));
    r.query_token = "s3cret-token";
    CHECK_FALSE(refusal(p, r));
    r.query_token.clear();
    r.cookie_token = "s3cret-token";
    CHECK_FALSE(refusal(p, r));
    r.cookie_token.clear();
    r.authorization = "Bearer s3cret-token";
    CHECK_FALSE(refusal(p, r));
    r.authorization = "Basic s3cret-token";
    CHECK(refusal(p, r));
    // The token does not make another site's page welcome.
    RequestFacts cross = get("plotter.local:8080", "http://evil.example");
    cross.cookie_token = "s3cret-token";
    CHECK(refusal(p, cross));
}

TEST_CASE("serve: the token cookie is the server's token, set for a right ?token= only",
          "[serve]") {
    AccessPolicy p;
    p.token = "s3cret";
    p.loopback = false;
    RequestFacts r;
    r.method = "GET";
    r.query_token = "s3cret";
    CHECK(token_cookie(p, r, "pathstream_token") ==
          "pathstream_token=s3cret; Path=/; HttpOnly; SameSite=Strict");
    // A wrong ?token= next to a right Bearer header passes the check, but its bytes (cookie
    // attributes here) never reach Set-Cookie.
    r.authorization = "Bearer s3cret";
    r.query_token = "x; Domain=evil.example; Max-Age=99999999";
    CHECK_FALSE(refusal(p, r));
    CHECK_FALSE(token_cookie(p, r, "pathstream_token"));
    r.query_token.clear();
    CHECK_FALSE(token_cookie(p, r, "pathstream_token"));
    CHECK_FALSE(token_cookie(AccessPolicy{}, r, "pathstream_token"));  // no token configured
    CHECK_FALSE(token_problem("a1B2-c3_D4.e5~"));
    CHECK(token_problem("a;b"));
    CHECK(token_problem("a b"));
    CHECK(token_problem("\"x\""));
    CHECK(token_problem(""));
}

TEST_CASE("serve: upload names stay inside the server's directory", "[serve]") {
    CHECK(upload_file_name("landscape.svg") == "landscape.svg");
    CHECK(upload_file_name("../../etc/x.svg") == "x.svg");
    CHECK(upload_file_name("C:\\drawings\\leaf.NGC") == "leaf.NGC");
    CHECK(upload_file_name("my drawing (1).svg") == "my_drawing__1_.svg");
    CHECK(upload_file_name("...hidden.json") == "hidden.json");
    // Never an option of the commands it is handed to.
    CHECK(upload_file_name("-h.csv") == "_h.csv");
    CHECK(upload_file_name("--machine=x.json") == "__machine_x.json");
    CHECK(upload_file_name("-mfoo.csv") == "_mfoo.csv");
    CHECK(upload_file_name(".-h.svg") == "_h.svg");
    CHECK_THROWS_AS(upload_file_name("passwd"), std::invalid_argument);
    CHECK_THROWS_AS(upload_file_name("x.exe"), std::invalid_argument);
    CHECK_THROWS_AS(upload_file_name("../"), std::invalid_argument);
    CHECK(upload_file_name(std::string(300, 'a') + ".svg").size() == 100);
}

TEST_CASE("serve: the page's options become path-option arguments", "[serve]") {
    const auto args = path_arguments(nlohmann::json{{"fit", "a4-landscape"},
                                                    {"margin", 10},
                                                    {"rotate", 90},
                                                    {"flip_y", true},
                                                    {"keep_order", false},
                                                    {"layers", {"2", "--machine=/etc/passwd"}},
                                                    {"pause", "none"}});
    // The box "Order for less travel" on: --order, so that G-code is ordered too (its default
    // keeps the program's order).
    const std::vector<std::string> want = {
        "--fit=a4-landscape", "--flip-y",    "--layer=--machine=/etc/passwd",
        "--layer=2",          "--margin=10", "--order",
        "--pause=none",       "--rotate=90"};
    std::vector<std::string> sorted = args;
    std::sort(sorted.begin(), sorted.end());
    CHECK(sorted == want);
    CHECK(path_arguments(nlohmann::json::object()).empty());
    CHECK(path_arguments({{"keep_order", true}}) == std::vector<std::string>{"--keep-order"});
    CHECK_THROWS_AS(path_arguments({{"machine", "x.json"}}), std::invalid_argument);
    CHECK_THROWS_AS(path_arguments({{"fit", "a9"}}), std::invalid_argument);
    CHECK_THROWS_AS(path_arguments({{"rotate", 45}}), std::invalid_argument);
    CHECK_THROWS_AS(path_arguments({{"margin", -1}}), std::invalid_argument);
    CHECK_THROWS_AS(path_arguments({{"flip_y", "yes"}}), std::invalid_argument);
    CHECK_THROWS_AS(path_arguments({{"layers", "1"}}), std::invalid_argument);
    CHECK_THROWS_AS(path_arguments(nlohmann::json::array()), std::invalid_argument);
}

TEST_CASE("serve: the preview follows the plan's spans and figures", "[serve]") {
    MachineProfile m;
    m.axes = {{"x", 250, 3000}, {"y", 250, 3000}};
    m.axes[0].travel_min = 0;
    m.axes[0].travel_max = 300;
    m.axes[1].travel_min = 0;
    m.axes[1].travel_max = 200;
    m.axes[0].has_travel = m.axes[1].has_travel = true;
    Path path;
    Subpath line;
    line.basis = PathBasis::kPolyline;
    line.points = {{10, 10}, {110, 10}};  // one straight line: planned as many spans
    Subpath corner;
    corner.basis = PathBasis::kPolyline;
    corner.points = {{10, 50}, {60, 50}, {60, 100}};
    path.subpaths = {line, corner};
    const Plan plan = plan_path(to_bezier_segments(path), m);
    REQUIRE(plan.spans.size() > 20);
    const nlohmann::ordered_json p = preview_json(plan, path, m);
    CHECK(p["summary"]["duration_s"].get<double>() == plan.duration);
    CHECK(p["summary"]["ticks"].get<std::uint64_t>() == plan.total_ticks);
    CHECK(p["summary"]["travel_length_mm"].get<double>() == plan.travel_length);
    CHECK(p["summary"]["drawn_length_mm"].get<double>() == plan.path_length);
    CHECK(p["summary"]["subpaths"] == 2);
    CHECK(p["work_area"]["x_max"] == 300);
    const auto& x = p["path"]["x"];
    const auto& y = p["path"]["y"];
    const auto& tick = p["path"]["tick"];
    const auto& pen = p["path"]["pen"];
    REQUIRE(x.size() == tick.size());
    REQUIRE(pen.size() == tick.size());
    // Straight pieces collapse: the line, the travel and the corner's two legs, with the
    // pen-down and pen-up rests where the pen changes.
    CHECK(x.size() < 24);
    CHECK(x.size() * 5 < plan.spans.size());
    CHECK(x.front().get<double>() == Approx(10).margin(1e-9));
    CHECK(y.front().get<double>() == Approx(10).margin(1e-9));
    CHECK(x.back().get<double>() == Approx(60).margin(1e-9));
    CHECK(y.back().get<double>() == Approx(100).margin(1e-9));
    CHECK(tick.front() == 0);
    CHECK(tick.back().get<std::uint64_t>() == plan.total_ticks);
    CHECK(std::is_sorted(tick.begin(), tick.end()));
    // The corner at (60, 50) is kept, drawn with the pen down.
    bool corner_kept = false;
    for (std::size_t i = 0; i < x.size(); ++i) {
        if (std::abs(x[i].get<double>() - 60) < 1e-3 && std::abs(y[i].get<double>() - 50) < 1e-3 &&
            pen[i] == 1)
            corner_kept = true;
    }
    CHECK(corner_kept);
    CHECK(std::count(pen.begin(), pen.end(), 0) >= 1);  // the travel between the subpaths
    CHECK(p["speed"]["v"].size() == p["speed"]["t"].size());
    const auto& v = p["speed"]["v"];
    CHECK(*std::max_element(v.begin(), v.end()) <= 250 * std::sqrt(2.0) + 1e-6);
}

TEST_CASE("serve: a listener gets every event in order while another thread publishes",
          "[serve][threads]") {
    EventHub hub(100000);
    constexpr std::uint64_t kEvents = 20000;
    std::vector<std::uint64_t> seen;
    std::uint64_t missed = 0;
    std::thread listener([&] {
        std::uint64_t after = 0;
        while (after < kEvents) {
            std::uint64_t m = 0;
            for (const HubEvent& e : hub.wait_after(after, std::chrono::milliseconds(200), &m)) {
                seen.push_back(std::stoull(e.json));
                after = e.sequence;
            }
            missed += m;
        }
    });
    std::thread publisher([&] {
        for (std::uint64_t i = 1; i <= kEvents; ++i)
            hub.publish(std::to_string(i), i % 100 == 0 ? "hundreds" : "");
    });
    publisher.join();
    listener.join();
    CHECK(missed == 0);
    REQUIRE(seen.size() == kEvents);
    for (std::uint64_t i = 0; i < kEvents; ++i) REQUIRE(seen[i] == i + 1);
    std::uint64_t after = 0;
    const auto sticky = hub.sticky(after);
    REQUIRE(sticky.size() == 1);
    CHECK(sticky[0].json == std::to_string(kEvents));
    CHECK(after == kEvents);
}

TEST_CASE("serve: a slow listener misses the oldest events and is told how many",
          "[serve][threads]") {
    EventHub hub(64);
    std::thread publisher([&] {
        for (int i = 1; i <= 5000; ++i) hub.publish(std::to_string(i));
    });
    publisher.join();
    std::thread listener([&] {
        std::uint64_t missed = 0;
        const auto events = hub.wait_after(0, std::chrono::milliseconds(0), &missed);
        CHECK(events.size() == 64);
        CHECK(missed == 5000 - 64);
        CHECK(events.front().sequence == missed + 1);
    });
    listener.join();
    hub.close();
    CHECK(hub.wait_after(0, std::chrono::milliseconds(1000)).empty());  // closed: at once, nothing
}

TEST_CASE("serve: seeded interleavings of publishers and listeners keep order and counts",
          "[serve]") {
    std::mt19937 random(20261126);
    for (int round = 0; round < 50; ++round) {
        const std::size_t capacity = 1 + random() % 40;
        EventHub hub(capacity);
        std::vector<std::uint64_t> cursor(3, 0), received(3, 0), missed(3, 0);
        std::uint64_t published = 0;
        for (int step = 0; step < 400; ++step) {
            const unsigned who = random() % 4;
            if (who == 3) {
                hub.publish(std::to_string(++published), random() % 5 == 0 ? "k" : "");
                continue;
            }
            std::uint64_t m = 0;
            const auto events = hub.wait_after(cursor[who], std::chrono::milliseconds(0), &m);
            missed[who] += m;
            for (const HubEvent& e : events) {
                REQUIRE(e.sequence == cursor[who] + 1 + (&e == &events.front() ? m : 0));
                REQUIRE(std::stoull(e.json) == e.sequence);
                cursor[who] = e.sequence;
                ++received[who];
            }
        }
        for (unsigned who = 0; who < 3; ++who) {
            std::uint64_t m = 0;
            for (const HubEvent& e :
                 hub.wait_after(cursor[who], std::chrono::milliseconds(0), &m)) {
                cursor[who] = e.sequence;
                ++received[who];
            }
            missed[who] += m;
            REQUIRE(received[who] + missed[who] == published);
        }
    }
}

TEST_CASE("serve: a child's output, error text and exit status", "[serve]") {
    const ChildOutput r =
        run_child({"/bin/sh", "-c", "echo one; echo two; echo oops >&2; printf tail; exit 3"}, "/");
    CHECK(r.exit_code == 3);
    CHECK(r.out == "one\ntwo\ntail\n");
    CHECK(r.err == "oops\n");
    const ChildOutput killed = run_child({"/bin/sh", "-c", "kill -TERM $$"}, "/tmp");
    CHECK(killed.exit_code == 128 + 15);
    CHECK_THROWS_AS(run_child({"/nonexistent/program"}, "/"), std::system_error);
}

TEST_CASE("serve: the preview of a streamed plan has the whole plan's path and figures",
          "[serve]") {
    MachineProfile m;
    m.axes = {{"x", 250, 3000}, {"y", 250, 3000}};
    Path path;
    std::mt19937_64 rng(41);
    std::uniform_real_distribution<double> d(0, 150);
    for (int k = 0; k < 6; ++k) {
        Subpath s;
        s.basis = k % 2 == 0 ? PathBasis::kBSpline : PathBasis::kPolyline;
        for (int i = 0; i < 40; ++i) s.points.push_back({d(rng), d(rng)});
        path.subpaths.push_back(s);
    }
    PreviewOptions few;
    few.speed_samples = 50;
    const Plan plan = plan_path(to_bezier_segments(path), m);
    const nlohmann::ordered_json whole = preview_json(plan, path, m, few);
    PreviewRecorder recorder(path, m, few);
    for (const CoreSpan& s : plan.spans) recorder.span(s);
    const nlohmann::ordered_json streamed = recorder.finish(
        plan.duration, plan.total_ticks, plan.pen.size(), plan.path_length, plan.travel_length);
    CHECK(streamed["summary"] == whole["summary"]);
    CHECK(streamed["path"] == whole["path"]);
    CHECK(streamed["speed"]["t"] == whole["speed"]["t"]);
    // Speeds: each bin takes the fastest fine bin starting in it, so a span near a boundary
    // may count in the bin before; the fastest speed of the job is the same.
    const auto& a = streamed["speed"]["v"];
    const auto& b = whole["speed"]["v"];
    REQUIRE(a.size() == b.size());
    double fastest_a = 0, fastest_b = 0, total_a = 0, total_b = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        fastest_a = std::max(fastest_a, a[i].get<double>());
        fastest_b = std::max(fastest_b, b[i].get<double>());
        total_a += a[i].get<double>();
        total_b += b[i].get<double>();
    }
    CHECK(fastest_a == fastest_b);
    CHECK(total_a == Approx(total_b).epsilon(0.1));
}
