#include "server.hpp"

#include <signal.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "drawing_request.hpp"
#include "http_server.hpp"
#include "operator_command.hpp"
#include "pathstream/host/device_link.hpp"
#include "pathstream/host/job_journal.hpp"
#include "pathstream/host/placement.hpp"
#include "pathstream/host/progress.hpp"
#include "pathstream/machine/device_setup.hpp"
#include "serve/web_assets.hpp"

namespace pathstream::host::serve {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

/// A handler's answer: an HTTP status and a JSON body.
struct Server::Reply {
    int status = 200;
    Json body;
};

namespace {

Json error_body(const std::string& message) {
    return Json{{"ok", false}, {"error", message}};
}

void replace_all(std::string& text, const std::string& what, const std::string& with) {
    if (what.empty()) return;
    for (std::size_t at = text.find(what); at != std::string::npos;
         at = text.find(what, at + with.size())) {
        text.replace(at, what.size(), with);
    }
}

// The paper a fit names, where placement puts it (from the machine's origin), with the margin
// the drawing keeps from its edges; null for no fit or a fit to the work area.
Json paper_json(const nlohmann::json& options) {
    if (!options.is_object() || !options.contains("fit") || !options["fit"].is_string())
        return nullptr;
    const std::string fit = options["fit"].get<std::string>();
    if (fit.empty() || fit == "area") return nullptr;
    const Box2 b = paper_box(fit);
    const nlohmann::json margin = options.value("margin", nlohmann::json(0));
    return Json{{"name", fit},      {"x_min", b.x_min},
                {"y_min", b.y_min}, {"x_max", b.x_max},
                {"y_max", b.y_max}, {"margin_mm", margin.is_number() ? margin.get<double>() : 0.0}};
}

std::string number_text(double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%.6f", v);
    return text;
}

}  // namespace

Server::Server(ServerConfig config, MachineProfile machine)
    : config_(std::move(config)), machine_(std::move(machine)) {
    HttpLimits limits = config_.limits;
    limits.body_bytes = config_.max_upload_bytes;
    http_ = std::make_unique<HttpServer>(limits, hub_);
    fs::create_directories(fs::path(config_.state_dir) / "drawing");
    routes();
}

Server::~Server() {
    stop();
    http_.reset();
    if (poller_.joinable()) poller_.join();
    if (job_thread_.joinable()) job_thread_.join();
}

void Server::bind() {
    bound_port_ = http_->bind(config_.listen_host, config_.port);
    config_.access.port = bound_port_;
}

void Server::start_mqtt() {
    if (!config_.mqtt) return;
    Json axes = Json::array();
    for (const AxisLimits& a : machine_.axes) axes.push_back(a.name);
    const Json identity{{"name", config_.mqtt->name},
                        {"kind", config_.mqtt->kind},
                        {"machine", fs::path(config_.machine_file).filename().string()},
                        {"axes", axes},
                        {"target", config_.target}};
    const auto plain = [](const Reply& r) {
        return std::make_pair(r.status, nlohmann::json::parse(r.body.dump()));
    };
    JobDeskHooks hooks;
    hooks.start = [this, plain](const JobMessage& job) {
        // A token each: the run's claim on planning cancels the newest plan before it, the
        // upload's.
        const CancelToken stored_plan, run_plan;
        const Reply stored = upload(job.file, job.drawing, job.options, stored_plan);
        if (stored.status != 200) return plain(stored);
        try {
            return plain(run_job(job.options, "", run_plan));
        } catch (const std::exception& e) {
            return std::make_pair(
                422, nlohmann::json{{"ok", false}, {"error", clean_message(e.what())}});
        }
    };
    hooks.resume = [this, plain] { return plain(resume()); };
    hooks.busy = [this] { return job_running(); };
    hooks.publish = [this](const std::string& topic, const std::string& payload, int qos,
                           bool retain) { mqtt_->publish(topic, payload, qos, retain); };
    desk_ = std::make_unique<JobDesk>(config_.mqtt->name, config_.mqtt->kind, config_.state_dir,
                                      config_.max_upload_bytes, std::move(hooks));
    mqtt_ = std::make_unique<MqttBridge>(
        *config_.mqtt, hub_,
        [this](const Json& request) {
            const Reply r = control(request);
            return std::make_pair(r.status, r.body);
        },
        identity, desk_.get());
    mqtt_->start();
}

void Server::run() {
    poller_ = std::thread([this] { poll_device(); });
    http_->run();
}

void Server::stop() {
    if (stopping_.exchange(true)) return;
    {
        // A job that streams is asked to hold at the next span boundary: the machine stops
        // drawing with the rest of the job kept, and the journal resumes it.
        const std::lock_guard<std::mutex> lock(job_mutex_);
        if (job_ && job_running_.load() && job_kind_ == "stream") job_->signal(SIGTERM);
    }
    if (mqtt_) mqtt_->stop();
    hub_.close();
    http_->stop();
}

std::string Server::drawing_file() const {
    const std::lock_guard<std::mutex> lock(drawing_mutex_);
    return drawing_name_;
}

std::string Server::drawing_hash() const {
    const std::lock_guard<std::mutex> lock(drawing_mutex_);
    return drawing_hash_;
}

// Messages name the drawing as the page knows it and never the server's directory (by
// default a temporary one, gone with the server): the command line's "resume with pathstream
// stream --resume JOURNAL" is the page's Resume job.
std::string Server::clean_message(std::string message) const {
    const fs::path state(config_.state_dir);
    replace_all(message, "pathstream stream --resume " + (state / "job.journal.json").string(),
                "Resume job on the page");
    replace_all(message, (state / "drawing").string() + "/", "");
    replace_all(message, state.string() + "/", "");
    replace_all(message, state.string(), "the server's state directory");
    return message;
}

std::vector<std::string> Server::arguments(const nlohmann::json& options) const {
    std::vector<std::string> args = path_arguments(options);
    // The order starts where the pen is, as `stream` orders it: the preview and the run then
    // plan the same drawing.
    const std::lock_guard<std::mutex> lock(device_mutex_);
    if (!rest_mm_.empty()) {
        std::string start = "--order-start=";
        for (std::size_t a = 0; a < rest_mm_.size(); ++a)
            start += (a ? "," : "") + number_text(rest_mm_[a]);
        args.push_back(start);
    }
    return args;
}

// The preview planned by `pathstream plan --preview` in a child process: killed when its
// client leaves, a newer plan replaces it, the server stops or it passes the time budget,
// and whatever memory it took is the system's again when it ends.
Json Server::plan_preview(const std::vector<std::string>& args, const CancelToken& cancel) {
    const std::string name = drawing_file();
    if (name.empty()) throw std::invalid_argument("no drawing loaded");
    if (cancel.cancelled()) throw std::runtime_error("planning cancelled");
    std::vector<std::string> argv = {config_.executable, "plan",
                                     "--machine=" + config_.machine_file, "--preview",
                                     "--max-motion=" + number_text(config_.max_motion_s)};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--", name});
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(config_.plan_timeout_s);
    bool late = false;
    double estimated_s = -1;
    std::string document, errors;
    ChildProcess child(argv, (fs::path(config_.state_dir) / "drawing").string());
    const int exit_code = child.wait(
        [&](const std::string& line) {
            if (line.rfind("{\"event\":\"planning\"", 0) == 0) {
                const nlohmann::json e = nlohmann::json::parse(line, nullptr, false);
                if (e.is_object() && e.value("estimated_s", -1.0) >= 0)
                    estimated_s = e.value("estimated_s", -1.0);
                hub_.publish(line);
                return;
            }
            document = line;
        },
        errors,
        [&] {
            late = std::chrono::steady_clock::now() > deadline;
            return late || cancel.cancelled() || stopping_.load();
        });
    if (late) {
        std::string message = "planning stopped after " + duration_text(config_.plan_timeout_s) +
                              " (serve --plan-timeout)";
        if (estimated_s >= 0) message += ": the job moves for about " + duration_text(estimated_s);
        throw std::runtime_error(message);
    }
    if (cancel.cancelled() || stopping_.load()) throw std::runtime_error("planning cancelled");
    if (exit_code != 0) throw std::runtime_error(last_lines(errors, 1));
    Json p = Json::parse(document);
    p["drawing"] = name;
    p["drawing_hash"] = drawing_hash();
    std::vector<double> start;
    {
        const std::lock_guard<std::mutex> device_lock(device_mutex_);
        start = rest_mm_;
    }
    p["rest_mm"] = start;
    return p;
}

Json Server::placed_preview(const nlohmann::json& options, const CancelToken& cancel) {
    try {
        Json p = plan_preview(arguments(options), cancel);
        p["paper"] = paper_json(options);
        p["options"] = options.is_object() ? Json(options) : Json::object();
        const std::lock_guard<std::mutex> lock(preview_mutex_);
        last_preview_ = p;
        return p;
    } catch (...) {
        // What the pages show is what Start would run: a drawing that cannot be planned has
        // no preview.
        const std::lock_guard<std::mutex> lock(preview_mutex_);
        last_preview_ = nullptr;
        throw;
    }
}

Server::Reply Server::last_preview() const {
    const std::lock_guard<std::mutex> lock(preview_mutex_);
    if (last_preview_.is_null())
        return {404, error_body("no preview: no drawing is loaded, or it could not be planned")};
    Json p = last_preview_;
    p["ok"] = true;
    return {200, p};
}

// The whole job's ticks as its first stream planned them (stream --plan-first), kept next to
// its journal: a resumed job is counted as a part of it.
void Server::remember_whole_job(const std::string& job_start_line) {
    try {
        const nlohmann::json e = nlohmann::json::parse(job_start_line);
        if (!e.contains("plan_ticks") || !e["plan_ticks"].is_number_unsigned()) return;
        const std::uint64_t ticks = e["plan_ticks"].get<std::uint64_t>();
        std::ofstream out(fs::path(config_.state_dir) / "job.whole.json", std::ios::trunc);
        out << Json{{"plan_ticks", ticks}}.dump() << "\n";
    } catch (const std::exception&) {
        // Not a job_start line the page can count on: a resumed job then counts for itself.
    }
}

Json Server::whole_job_ticks() const {
    std::ifstream in(fs::path(config_.state_dir) / "job.whole.json");
    if (!in) return nullptr;
    try {
        const nlohmann::json j = nlohmann::json::parse(in);
        if (j.contains("plan_ticks") && j["plan_ticks"].is_number_unsigned())
            return j["plan_ticks"].get<std::uint64_t>();
    } catch (const std::exception&) {
    }
    return nullptr;
}

void Server::claim_planning(const CancelToken& cancel) {
    const std::lock_guard<std::mutex> lock(newest_plan_mutex_);
    newest_plan_.cancel();
    newest_plan_ = cancel;
}

Server::Reply Server::upload(const std::string& given_name, const std::string& body,
                             const nlohmann::json& options, const CancelToken& cancel) {
    const std::string name = upload_file_name(given_name);
    const fs::path dir = fs::path(config_.state_dir) / "drawing";
    claim_planning(cancel);
    const std::lock_guard<std::mutex> gate(gate_);
    if (job_running()) return {409, error_body("a job is running: wait for it to end, or stop it")};
    {
        const std::lock_guard<std::mutex> lock(drawing_mutex_);
        for (const auto& entry : fs::directory_iterator(dir)) fs::remove_all(entry.path());
        std::ofstream out(dir / name, std::ios::binary);
        out.write(body.data(), static_cast<std::streamsize>(body.size()));
        if (!out.flush()) return {500, error_body("cannot store the drawing")};
        drawing_name_ = name;
        drawing_hash_ = content_hash(body);
    }
    try {
        Json p = placed_preview(options, cancel);
        p["ok"] = true;
        return {200, p};
    } catch (const std::exception& e) {
        // Stored but not planned (a reader's error, a placement that does not fit): the page
        // shows no preview, and other options may place it.
        Json answer = error_body(clean_message(e.what()));
        answer["drawing"] = name;
        return {422, answer};
    }
}

Server::Reply Server::preview(const nlohmann::json& options, const CancelToken& cancel) {
    claim_planning(cancel);
    const std::lock_guard<std::mutex> gate(gate_);
    Json p = placed_preview(options, cancel);
    p["ok"] = true;
    return {200, p};
}

bool Server::job_running() const {
    return job_running_.load();
}

bool Server::start_child(const std::string& kind, std::vector<std::string> argv,
                         const Json& whole_ticks) {
    const std::lock_guard<std::mutex> lock(job_mutex_);
    if (job_running_.load() || stopping_.load()) return false;
    if (job_thread_.joinable()) job_thread_.join();
    job_ = std::make_unique<ChildProcess>(argv, (fs::path(config_.state_dir) / "drawing").string());
    job_kind_ = kind;
    stop_requested_.store(false);
    job_running_.store(true);
    for (const char* k : {"job_start", "progress", "job_end", "pause"}) hub_.forget(k);
    hub_.publish(Json{{"event", "process"},
                      {"kind", kind},
                      {"running", true},
                      {"drawing", drawing_file()},
                      {"whole_plan_ticks", whole_ticks}}
                     .dump(),
                 "process");
    job_thread_ = std::thread([this, kind, child = job_.get()] {
        std::string errors, outcome;
        const int exit_code = child->wait(
            [&](const std::string& line) {
                const std::string sticky = job_sticky_kind(line);
                if (sticky == "job_end") {
                    for (const char* o : {"finished", "held", "stopped", "failed"}) {
                        if (line.find(std::string("\"outcome\":\"") + o + "\"") !=
                            std::string::npos)
                            outcome = o;
                    }
                }
                if (sticky == "job_start" && kind == "stream") remember_whole_job(line);
                hub_.publish(line, sticky);
                // The stream holds at the first signal and says so; a second one stops it.
                if (sticky.empty() && stop_requested_.load() &&
                    line.find("\"event\":\"hold\"") != std::string::npos) {
                    child->signal(SIGTERM);
                }
            },
            errors);
        // A hold that came to rest before the second signal was seen: the stop drops the
        // queue as `ctl stop` does (the journal resumes from where the device rests).
        if (stop_requested_.load() && outcome == "held") {
            const ChildOutput r =
                run_child({config_.executable, "ctl", "--wait=10", "--", config_.target, "stop"},
                          config_.state_dir);
            hub_.publish(
                Json{{"event", "command"},
                     {"verb", "stop"},
                     {"ok", r.exit_code == 0},
                     {"error", r.exit_code == 0 ? "" : clean_message(last_lines(r.err, 1))}}
                    .dump());
        }
        Json end{{"event", "process"}, {"kind", kind}, {"running", false}, {"exit", exit_code}};
        end["report"] = clean_message(last_lines(errors, 12));
        if (exit_code != 0) end["error"] = clean_message(last_lines(errors, 1));
        hub_.publish(end.dump(), "process");
        job_running_.store(false);
        if (desk_) desk_->job_ended(outcome, exit_code, end.value("error", std::string()));
    });
    return true;
}

Server::Reply Server::run_job(const nlohmann::json& options, const std::string& previewed_hash,
                              const CancelToken& cancel) {
    claim_planning(cancel);
    // Upload, preview and run one at a time: the file streamed is the one this plan previews.
    const std::lock_guard<std::mutex> gate(gate_);
    if (job_running()) return {409, error_body("a job is running already")};
    const std::string name = drawing_file();
    if (!previewed_hash.empty() && previewed_hash != drawing_hash()) {
        return {409, error_body("the drawing changed since this page's preview: " + name +
                                " is loaded now")};
    }
    const std::vector<std::string> args = arguments(options);
    Json p = placed_preview(options,
                            cancel);  // throws for a drawing that cannot be planned: nothing starts
    std::vector<std::string> argv = {config_.executable, "stream"};
    // --plan-first: the page shows the job's length from job_start on (web/app.js reads it
    // there), which a stream planned as it goes only knows at its end.
    for (const std::string& a :
         {std::string("--machine=") + config_.machine_file, "--target=" + config_.target,
          std::string("--lead-in"), std::string("--plan-first"), std::string("--events=-"),
          // Start on the page draws anew: the last job's journal goes
          // (Resume job continues it instead).
          std::string("--replace-journal"), "--events-rate=" + number_text(config_.events_rate),
          "--journal=" + (fs::path(config_.state_dir) / "job.journal.json").string()}) {
        argv.push_back(a);
    }
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--", name});
    if (!start_child("stream", argv)) return {409, error_body("a job is running already")};
    p["ok"] = true;
    return {200, p};
}

Server::Reply Server::resume() {
    const fs::path journal = fs::path(config_.state_dir) / "job.journal.json";
    if (!fs::exists(journal))
        return {409, error_body("no job journal: nothing was streamed from this page yet")};
    const std::vector<std::string> argv = {config_.executable,
                                           "stream",
                                           "--resume=" + journal.string(),
                                           "--events=-",
                                           "--events-rate=" + number_text(config_.events_rate),
                                           "--"};
    if (!start_child("resume", argv, whole_job_ticks()))
        return {409, error_body("a job is running already")};
    return {200, Json{{"ok", true}}};
}

Server::Reply Server::simulate(const nlohmann::json& options, const CancelToken& cancel) {
    claim_planning(cancel);
    const std::lock_guard<std::mutex> gate(gate_);
    const std::string name = drawing_file();
    if (name.empty()) return {409, error_body("no drawing loaded")};
    std::vector<std::string> argv = {config_.executable, "sim",
                                     "--machine=" + config_.machine_file};
    const std::vector<std::string> args = arguments(options);
    argv.insert(argv.end(), args.begin(), args.end());
    argv.insert(argv.end(), {"--", name});
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::duration<double>(config_.plan_timeout_s);
    bool late = false;
    const ChildOutput r = run_child(argv, (fs::path(config_.state_dir) / "drawing").string(), [&] {
        late = std::chrono::steady_clock::now() > deadline;
        return late || cancel.cancelled() || stopping_.load();
    });
    if (late)
        return {422, error_body("the simulation stopped after " +
                                duration_text(config_.plan_timeout_s) + " (serve --plan-timeout)")};
    Json body{{"ok", r.exit_code == 0}, {"exit", r.exit_code}, {"report", clean_message(r.out)}};
    if (r.exit_code != 0) body["error"] = clean_message(last_lines(r.err, 3));
    return {r.exit_code == 0 ? 200 : 422, body};
}

Server::Reply Server::control(const nlohmann::json& request) {
    if (!request.is_object() || !request.contains("verb") || !request["verb"].is_string()) {
        return {400, error_body("want {\"verb\": ...}")};
    }
    const std::string verb = request["verb"].get<std::string>();
    if (verb == "stop" && job_running()) {
        // The job's own stream stops the device (a hold, then a stop that drops the queue)
        // and records it in the journal: the first signal now, the second once it holds.
        const std::lock_guard<std::mutex> lock(job_mutex_);
        if (job_) {
            stop_requested_.store(true);
            job_->signal(SIGTERM);
        }
        return {200, Json{{"ok", true}, {"message", "stopping the job"}}};
    }
    const auto [status, answer] = run_operator_command(
        {config_.executable, config_.machine_file, config_.target, config_.state_dir}, machine_,
        request, [this] { return stopping_.load(); });
    if (status == 400) return {400, error_body(answer.value("error", std::string()))};
    const bool ok = status == 200;
    const std::string error = ok ? "" : clean_message(answer.value("error", std::string()));
    Json body{{"ok", ok}, {"verb", verb}};
    if (answer.contains("result")) body["result"] = Json::parse(answer["result"].dump());
    if (!ok) body["error"] = error;
    hub_.publish(Json{{"event", "command"}, {"verb", verb}, {"ok", ok}, {"error", error}}.dump());
    return {status, body};
}

Json Server::state() const {
    Json axes = Json::array();
    for (const AxisLimits& a : machine_.axes) {
        axes.push_back({{"name", a.name},
                        {"travel_min", a.travel_min},
                        {"travel_max", a.travel_max},
                        {"max_velocity", a.max_velocity}});
    }
    const fs::path journal = fs::path(config_.state_dir) / "job.journal.json";
    Json s{{"ok", true},
           {"machine",
            {{"file", fs::path(config_.machine_file).filename().string()},
             {"axes", axes},
             {"tick_hz", machine_.tick_hz}}},
           {"target", config_.target},
           {"drawing", drawing_file()},
           {"job_running", job_running()},
           {"journal", fs::exists(journal)},
           {"max_upload_bytes", config_.max_upload_bytes}};
    return s;
}

void Server::poll_device() {
    LinkOptions options;
    options.link_timeout_seconds = 2;
    options.response_timeout_ms = 300;
    const auto period = std::chrono::duration<double>(1.0 / config_.status_hz);
    std::unique_ptr<DeviceLink> link;
    std::string last_error;
    while (!stopping_.load()) {
        const auto next = std::chrono::steady_clock::now() + period;
        try {
            if (!link) link = open_device_link(config_.target, options);
            const DeviceSnapshot s = link->status();
            Json position = Json::object(), homing = Json::object();
            std::vector<double> rest;
            for (unsigned a = 0; a < s.axes && a < kMaxAxes && a < machine_.axes.size(); ++a) {
                const double mm = s.position[a] * machine_.mm_per_lsb;
                position[machine_.axes[a].name] = mm;
                homing[machine_.axes[a].name] = axis_homing_name(s.homing[a].state);
                rest.push_back(mm);
            }
            {
                const std::lock_guard<std::mutex> lock(device_mutex_);
                rest_mm_ = rest;
            }
            Json e{{"event", "device"},
                   {"state", device_state_name(s.state)},
                   {"code", s.state},
                   {"fault", s.fault_code == 0 ? "" : fault_text(s.fault_code)},
                   {"pen_down", s.pen_down()},
                   {"paused", s.paused()},
                   {"held_by_underrun", s.held_by_underrun()},
                   {"homing", s.homing_runs()},
                   {"queued_spans", s.queued},
                   {"ticks_executed", s.ticks_executed},
                   {"position_mm", position},
                   {"homed", homing}};
            hub_.publish(e.dump(), "device");
            last_error.clear();
        } catch (const std::exception& e) {
            link.reset();
            const std::string message = e.what();
            if (message != last_error)
                hub_.publish(Json{{"event", "device"}, {"error", message}}.dump(), "device");
            last_error = message;
            std::this_thread::sleep_for(std::chrono::milliseconds(500));
        }
        std::this_thread::sleep_until(next);
    }
}

namespace {

HttpResponse json_response(int status, const Json& body) {
    return {status, "application/json", body.dump(), {}};
}

// A stop goes to the lane no other work waits in. The body is small; anything larger is not a stop.
Lane control_lane(const HttpRequest& request) {
    if (request.body.size() > 4096) return Lane::command;
    const nlohmann::json j = nlohmann::json::parse(request.body, nullptr, false);
    return j.is_object() && j.value("verb", nlohmann::json()) == "stop" ? Lane::stop
                                                                        : Lane::command;
}

}  // namespace

void Server::routes() {
    HttpServer& h = *http_;
    h.on_head([this](const HttpRequest& req) {
        const RequestFacts facts = request_facts(req);
        HeadVerdict verdict;
        if (const auto why = refusal(config_.access, facts)) {
            verdict.refusal = json_response(403, error_body("refused: " + *why));
            return verdict;
        }
        verdict.headers = {{"Cache-Control", "no-store"},
                           {"X-Content-Type-Options", "nosniff"},
                           {"X-Frame-Options", "DENY"},
                           {"Referrer-Policy", "no-referrer"}};
        // The page keeps the token as a cookie that only this origin's requests carry.
        if (const auto cookie = token_cookie(config_.access, facts, kTokenCookie))
            verdict.headers.emplace_back("Set-Cookie", *cookie);
        return verdict;
    });
    const auto json_handler = [this](auto&& body) {
        return [this, body](const HttpRequest& req, const CancelToken& cancel) {
            Reply reply;
            try {
                nlohmann::json request =
                    req.body.empty() ? nlohmann::json::object() : nlohmann::json::parse(req.body);
                reply = body(req, request, cancel);
            } catch (const nlohmann::json::parse_error&) {
                reply = {400, error_body("the request body is not JSON")};
            } catch (const std::exception& e) {
                // Input errors (file:line:col), planning failures: what the CLI would print.
                reply = {422, error_body(clean_message(e.what()))};
            }
            return json_response(reply.status, reply.body);
        };
    };
    h.route("GET", "/api/state", Lane::command,
            json_handler([this](const HttpRequest&, const nlohmann::json&, const CancelToken&) {
                return Reply{200, state()};
            }));
    h.route("POST", "/api/drawing", Lane::work,
            [this](const HttpRequest& req, const CancelToken& cancel) {
                Reply reply;
                try {
                    nlohmann::json options = nlohmann::json::object();
                    if (req.has_param("options"))
                        options = nlohmann::json::parse(req.param("options"));
                    reply = upload(req.param("name"), req.body, options, cancel);
                } catch (const nlohmann::json::parse_error&) {
                    reply = {400, error_body("options: not JSON")};
                } catch (const std::exception& e) {
                    reply = {422, error_body(clean_message(e.what()))};
                }
                return json_response(reply.status, reply.body);
            });
    h.route("GET", "/api/preview", Lane::command, [this](const HttpRequest&, const CancelToken&) {
        const Reply reply = last_preview();
        return json_response(reply.status, reply.body);
    });
    h.route("POST", "/api/preview", Lane::work,
            json_handler(
                [this](const HttpRequest&, const nlohmann::json& j, const CancelToken& cancel) {
                    return preview(j.value("options", nlohmann::json::object()), cancel);
                }));
    h.route("POST", "/api/run", Lane::work,
            json_handler([this](const HttpRequest&, const nlohmann::json& j,
                                const CancelToken& cancel) {
                const nlohmann::json hash = j.value("drawing_hash", nlohmann::json(""));
                if (!hash.is_string())
                    throw std::invalid_argument("drawing_hash: want the preview's drawing_hash");
                return run_job(j.value("options", nlohmann::json::object()),
                               hash.get<std::string>(), cancel);
            }));
    h.route("POST", "/api/simulate", Lane::work,
            json_handler(
                [this](const HttpRequest&, const nlohmann::json& j, const CancelToken& cancel) {
                    return simulate(j.value("options", nlohmann::json::object()), cancel);
                }));
    h.route("POST", "/api/resume", Lane::command,
            json_handler([this](const HttpRequest&, const nlohmann::json&, const CancelToken&) {
                return resume();
            }));
    h.route("POST", "/api/control", control_lane,
            json_handler([this](const HttpRequest&, const nlohmann::json& j, const CancelToken&) {
                return control(j);
            }));
    h.events("/api/events");
    h.fallback([](const HttpRequest& req, const CancelToken&) {
        HttpResponse res;
        const WebAsset* asset = find_web_asset(req.path);
        if (!asset) {
            res.status = 404;
            res.body = error_body("no such page").dump();
            return res;
        }
        res.headers.emplace_back(
            "Content-Security-Policy",
            "default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'; "
            "connect-src 'self'; frame-ancestors 'none'");
        res.content_type = asset->content_type;
        res.body.assign(reinterpret_cast<const char*>(asset->data), asset->size);
        return res;
    });
}

}  // namespace pathstream::host::serve
