// `fleet serve`: the fleet page and a small JSON API on the HTTP server `serve` uses. The
// server holds no state of its own: the view is the broker's, a submission is published at
// once, a command waits for the machine's reply.
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <random>
#include <stdexcept>
#include <thread>

#include "fleet_actions.hpp"
#include "pathstream/host/fleet_job.hpp"
#include "serve/access.hpp"
#include "serve/http_server.hpp"
#include "serve/web_assets.hpp"

namespace pathstream::host {

namespace {

using Json = nlohmann::json;
using serve::HttpRequest;
using serve::HttpResponse;

constexpr std::size_t kPageJobs = 200;  // the newest jobs GET /api/fleet lists

std::atomic<bool> g_stop{false};
extern "C" void on_fleet_signal(int) {
    g_stop.store(true);
}

HttpResponse reply(int status, const Json& body) {
    return {status, "application/json", body.dump(), {}};
}

HttpResponse refuse(int status, const std::string& why) {
    return reply(status, Json{{"ok", false}, {"error", why}});
}

// The body as a JSON object, or nullopt.
std::optional<Json> body_object(const HttpRequest& req) {
    Json j = Json::parse(req.body, nullptr, false);
    if (!j.is_object()) return std::nullopt;
    return j;
}

std::string text_field(const Json& j, const char* key) {
    const auto it = j.find(key);
    if (it == j.end() || it->is_null()) return "";
    if (!it->is_string()) throw std::invalid_argument(std::string(key) + " must be a string");
    return it->get<std::string>();
}

bool known_machine(const FleetLink& link, const std::string& name) {
    bool known = false;
    link.read([&](const FleetView& v) { known = v.machine(name) != nullptr; });
    return known;
}

HttpResponse submit(FleetLink& link, const HttpRequest& req, std::size_t max_bytes) {
    const auto body = body_object(req);
    if (!body) return refuse(400, "a job is a JSON object: {\"file\", \"drawing\", ...}");
    FleetJobSpec spec;
    spec.max_bytes = max_bytes;
    try {
        spec.file_name = text_field(*body, "file");
        spec.drawing = text_field(*body, "drawing");
        spec.kind = text_field(*body, "kind");
        spec.machine = text_field(*body, "machine");
        spec.id = text_field(*body, "id");
        if (const std::string fit = text_field(*body, "fit"); !fit.empty())
            spec.options["fit"] = fit;
        if (const auto m = body->find("margin"); m != body->end() && !m->is_null()) {
            if (!m->is_number() || m->get<double>() < 0 || m->get<double>() > 1000)
                return refuse(400, "margin must be a number of mm, 0 to 1000");
            spec.options["margin"] = m->get<double>();
        }
    } catch (const std::invalid_argument& e) {
        return refuse(400, e.what());
    }
    if (spec.drawing.size() > max_bytes) {
        return refuse(413, "the drawing has " + std::to_string(spec.drawing.size()) +
                               " bytes, more than " + std::to_string(max_bytes));
    }
    if (!spec.machine.empty() && is_fleet_name(spec.machine)) {
        if (!known_machine(link, spec.machine))
            return refuse(404, "no machine named " + spec.machine + " on the broker");
        if (const std::string why = machine_refusal(link, spec.machine); !why.empty())
            return refuse(409, why);
    }
    thread_local std::mt19937_64 random(std::random_device{}());
    FleetJobMessages job;
    try {
        const double now =
            std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
                .count();
        job = build_fleet_job(spec, now, random);
    } catch (const std::invalid_argument& e) {
        return refuse(400, e.what());
    }
    link.publish(job.state_topic, job.state.dump(), 1, true);
    link.publish(job.topic, job.message.dump(), 1, false);
    return reply(200, Json{{"ok", true}, {"id", job.id}, {"topic", job.topic}});
}

HttpResponse command(FleetLink& link, const HttpRequest& req) {
    static const char* const verbs[] = {"hold", "resume", "stop",       "reset",   "home",
                                        "pen",  "jog",    "resume_job", "drop_job"};
    const auto body = body_object(req);
    if (!body) return refuse(400, "a command is a JSON object: {\"machine\", \"verb\", ...}");
    std::string machine, verb;
    try {
        machine = text_field(*body, "machine");
        verb = text_field(*body, "verb");
    } catch (const std::invalid_argument& e) {
        return refuse(400, e.what());
    }
    if (std::find(std::begin(verbs), std::end(verbs), verb) == std::end(verbs))
        return refuse(400, "unknown verb \"" + verb.substr(0, 40) + "\"");
    if (!is_fleet_name(machine) || !known_machine(link, machine))
        return refuse(404, "no machine named " + machine.substr(0, 80) + " on the broker");
    Json request{{"verb", verb}};
    for (const char* k : {"axis", "distance_mm", "down"}) {
        if (body->contains(k)) request[k] = (*body)[k];
    }
    const auto answer = link.command(machine, request, std::chrono::seconds(10));
    if (!answer) return refuse(504, "machine " + machine + " did not answer within 10 s");
    const Json status = answer->value("status", Json());
    return reply(status.is_number_integer() ? status.get<int>() : 502, *answer);
}

HttpResponse page(const HttpRequest& req) {
    // The fleet's own files only: the machine page (index.html, app.js) is serve's.
    const std::string path = req.path == "/" ? "/fleet.html" : req.path;
    const serve::WebAsset* asset = nullptr;
    if (path == "/fleet.html" || path == "/fleet.js" || path == "/style.css")
        asset = serve::find_web_asset(path);
    if (!asset) return refuse(404, "no such page");
    HttpResponse res;
    res.headers.emplace_back("Content-Security-Policy",
                             "default-src 'self'; style-src 'self'; script-src 'self'; "
                             "connect-src 'self'; frame-ancestors 'none'");
    res.content_type = asset->content_type;
    res.body.assign(reinterpret_cast<const char*>(asset->data), asset->size);
    return res;
}

std::string read_token(const FleetCommandOptions& o) {
    if (!o.token.empty() && !o.token_file.empty())
        throw std::invalid_argument("fleet serve: --token or --token-file, not both");
    std::string token = o.token;
    if (!o.token_file.empty()) {
        std::ifstream in(o.token_file);
        std::getline(in, token);
        while (!token.empty() && (token.back() == '\r' || token.back() == ' ')) token.pop_back();
    }
    if ((!o.token.empty() || !o.token_file.empty())) {
        if (const auto why = serve::token_problem(token))
            throw std::invalid_argument("fleet serve: the token: " + *why);
    }
    return token;
}

}  // namespace

int run_fleet_serve(FleetLink& link, const FleetCommandOptions& o) {
    const serve::ListenAddress listen = serve::parse_listen_address(o.listen);
    serve::AccessPolicy access;
    access.token = read_token(o);
    access.loopback = serve::is_loopback_host(listen.host);
    if (!access.loopback && access.token.empty()) {
        throw std::invalid_argument("fleet serve: --listen " + o.listen +
                                    " reaches beyond this machine: give --token or --token-file");
    }
    const std::size_t max_bytes = static_cast<std::size_t>(o.max_upload_mb * 1024 * 1024);
    serve::HttpLimits limits;
    // The drawing travels inside JSON: escapes may make it longer; its own size is checked
    // after parsing (413 with the figures).
    limits.body_bytes = 2 * max_bytes + 64 * 1024;
    serve::EventHub hub;
    serve::HttpServer http(limits, hub);
    access.port = http.bind(listen.host, listen.port);
    http.on_head([&access](const HttpRequest& req) {
        serve::HeadVerdict verdict;
        const serve::RequestFacts facts = serve::request_facts(req);
        if (const auto why = serve::refusal(access, facts)) {
            verdict.refusal = refuse(403, "refused: " + *why);
            return verdict;
        }
        verdict.headers = {{"Cache-Control", "no-store"},
                           {"X-Content-Type-Options", "nosniff"},
                           {"X-Frame-Options", "DENY"},
                           {"Referrer-Policy", "no-referrer"}};
        if (const auto cookie = serve::token_cookie(access, facts, serve::kTokenCookie))
            verdict.headers.emplace_back("Set-Cookie", *cookie);
        return verdict;
    });
    http.route("GET", "/api/fleet", serve::Lane::command,
               [&link](const HttpRequest&, const serve::CancelToken&) {
                   Json view = link.view_json();
                   view["broker"] = link.url().text();
                   // The page polls once a second: the newest jobs only, not 4096 histories.
                   Json& jobs = view["jobs"];
                   view["jobs_total"] = jobs.size();
                   if (jobs.size() > kPageJobs)
                       jobs.erase(jobs.begin() + static_cast<std::ptrdiff_t>(kPageJobs),
                                  jobs.end());
                   return reply(200, view);
               });
    http.route("POST", "/api/submit", serve::Lane::work,
               [&link, max_bytes](const HttpRequest& req, const serve::CancelToken&) {
                   return submit(link, req, max_bytes);
               });
    http.route(
        "POST", "/api/command", serve::Lane::command,
        [&link](const HttpRequest& req, const serve::CancelToken&) { return command(link, req); });
    http.fallback([](const HttpRequest& req, const serve::CancelToken&) { return page(req); });

    const bool v6 = listen.host.find(':') != std::string::npos;
    std::printf("pathstream fleet: http://%s:%u/%s for %s\n",
                v6 ? ("[" + listen.host + "]").c_str() : listen.host.c_str(), access.port,
                access.token.empty() ? "" : "?token=...", link.url().text().c_str());
    std::fflush(stdout);
    ::signal(SIGINT, on_fleet_signal);
    ::signal(SIGTERM, on_fleet_signal);
    ::signal(SIGPIPE, SIG_IGN);
    std::thread watcher([&] {
        while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
        http.stop();
    });
    http.run();
    g_stop.store(true);
    watcher.join();
    std::printf("pathstream fleet: stopped\n");
    return 0;
}

}  // namespace pathstream::host
