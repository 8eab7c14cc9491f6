#include "serve_command.hpp"

#include <signal.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "path_options.hpp"
#include "pathstream/host/planner.hpp"
#include "plan_command.hpp"
#include "serve/access.hpp"
#include "serve/child_process.hpp"
#include "serve/preview.hpp"
#include "serve/server.hpp"

namespace pathstream::host {

namespace fs = std::filesystem;

void add_serve_command(CLI::App& app, ServeCommandOptions& o) {
    CLI::App* cmd = app.add_subcommand("serve",
                                       "Serve a web page that loads, places, previews, simulates "
                                       "and streams drawings to a device and "
                                       "steers it (docs/serve.md)");
    cmd->add_option("--machine,-m", o.machine, "machine profile (JSON, docs/formats.md)")
        ->required()
        ->check(CLI::ExistingFile);
    cmd->add_option("--target,-t", o.target,
                    "device: modbus-tcp://HOST:PORT?unit=N, modbus-rtu:///dev/ttyX?... or "
                    "can://IFACE?node=N")
        ->required();
    cmd->add_option(
           "--listen", o.listen,
           "HOST:PORT to serve on; an address other than loopback needs --token or --token-file")
        ->capture_default_str();
    cmd->add_option("--token", o.token,
                    "a secret every request must carry (?token= once, then a cookie)");
    cmd->add_option("--token-file", o.token_file, "read the token from the first line of this file")
        ->check(CLI::ExistingFile);
    cmd->add_option(
        "--state-dir", o.state_dir,
        "directory for the uploaded drawing and the job journal (default: a new temporary one)");
    cmd->add_option("--max-upload-mb", o.max_upload_mb, "largest drawing accepted, MB")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 1024.0));
    cmd->add_option("--events-rate", o.events_rate, "progress updates per second sent to the page")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 50.0));
    cmd->add_option("--plan-timeout", o.plan_timeout,
                    "s a preview, run or simulation may plan before it is stopped")
        ->capture_default_str()
        ->check(CLI::Range(1.0, 86400.0));
    cmd->add_option("--max-motion-hours", o.max_motion_hours,
                    "refuse, before planning, a drawing estimated to move for longer")
        ->capture_default_str()
        ->check(CLI::Range(0.001, 1000.0));
    cmd->add_option("--max-connections", o.max_connections, "open connections in total")
        ->capture_default_str()
        ->check(CLI::Range(8, 100000));
    cmd->add_option("--max-connections-per-client", o.max_connections_per_client,
                    "open connections per client address")
        ->capture_default_str()
        ->check(CLI::Range(4, 100000));
    cmd->add_option("--mqtt", o.mqtt,
                    "report to this MQTT broker and take commands from it: "
                    "mqtt[s]://[USER[:PASSWORD]@]HOST[:PORT][?cafile=..&password_file=..] "
                    "(docs/mqtt.md)");
    cmd->add_option("--name", o.name,
                    "the machine's name on the broker (topics pathstream/NAME/...)")
        ->needs(cmd->get_option("--mqtt"));
    cmd->add_option("--kind", o.kind,
                    "with --mqtt: the job queue it takes jobs from besides \"any\" "
                    "(pathstream/queue/KIND; default: the profile's file name without .json)")
        ->needs(cmd->get_option("--mqtt"));
}

namespace {

std::atomic<bool> g_stop{false};
extern "C" void on_serve_signal(int) {
    g_stop.store(true);
}

std::string read_token(const ServeCommandOptions& o) {
    if (!o.token.empty() && !o.token_file.empty())
        throw std::invalid_argument("serve: --token or --token-file, not both");
    if (o.token_file.empty()) {
        if (o.token.empty()) return o.token;
        if (const auto why = serve::token_problem(o.token))
            throw std::invalid_argument("serve: --token: " + *why);
        return o.token;
    }
    std::ifstream in(o.token_file);
    std::string line;
    std::getline(in, line);
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    if (line.empty())
        throw std::invalid_argument("serve: --token-file " + o.token_file +
                                    ": the first line is empty");
    if (const auto why = serve::token_problem(line))
        throw std::invalid_argument("serve: --token-file " + o.token_file + ": " + *why);
    return line;
}

}  // namespace

int run_serve(const ServeCommandOptions& o) {
    serve::ServerConfig c;
    const serve::ListenAddress listen = serve::parse_listen_address(o.listen);
    c.listen_host = listen.host;
    c.port = listen.port;
    c.access.token = read_token(o);
    c.access.loopback = serve::is_loopback_host(listen.host);
    if (!c.access.loopback && c.access.token.empty()) {
        throw std::invalid_argument("serve: --listen " + o.listen +
                                    " reaches beyond this machine: give --token or --token-file");
    }
    c.machine_file = fs::absolute(o.machine).string();
    c.target = o.target;
    c.executable = serve::self_executable();
    c.events_rate = o.events_rate;
    c.max_upload_bytes = static_cast<std::size_t>(o.max_upload_mb * 1024 * 1024);
    c.plan_timeout_s = o.plan_timeout;
    c.max_motion_s = o.max_motion_hours * 3600;
    c.limits.connections = o.max_connections;
    c.limits.connections_per_client = o.max_connections_per_client;
    if (!o.mqtt.empty()) {
        if (o.name.empty()) throw std::invalid_argument("serve: --mqtt needs --name NAME");
        serve::check_machine_name(o.name);
        std::string kind = o.kind.empty() ? fs::path(o.machine).stem().string() : o.kind;
        // The profile's name may hold characters a topic level must not: the kind is checked
        // as a name is, and a stem that fails asks for --kind.
        try {
            serve::check_machine_name(kind);
        } catch (const std::invalid_argument&) {
            throw std::invalid_argument("serve: --kind \"" + kind +
                                        "\": only letters, digits, _ and - (it is part of topics)");
        }
        c.mqtt = serve::MqttLink{parse_mqtt_url(o.mqtt), o.name, kind};
    }
    bool temporary = false;
    if (o.state_dir.empty()) {
        std::string pattern = (fs::temp_directory_path() / "pathstream-serve-XXXXXX").string();
        if (::mkdtemp(pattern.data()) == nullptr)
            throw std::runtime_error("serve: cannot create a temporary directory");
        c.state_dir = pattern;
        temporary = true;
    } else {
        fs::create_directories(o.state_dir);
        c.state_dir = fs::absolute(o.state_dir).string();
    }
    MachineProfile machine = load_machine_profile(o.machine);
    int status = 0;
    {
        serve::Server server(c, machine);
        // Before anything is announced (the broker's online state, the address printed): a
        // signal sent as soon as the server shows up must stop it, not be lost (a background
        // job of a script starts with SIGINT ignored until this handler replaces that).
        ::signal(SIGINT, on_serve_signal);
        ::signal(SIGTERM, on_serve_signal);
        try {
            server.bind();
            server.start_mqtt();
        } catch (...) {
            if (temporary) {
                std::error_code ignored;
                fs::remove_all(c.state_dir, ignored);
            }
            throw;
        }
        std::printf("pathstream serve: http://%s:%u/%s for %s (machine %s)\n",
                    listen.host.find(':') != std::string::npos ? ("[" + listen.host + "]").c_str()
                                                               : listen.host.c_str(),
                    server.bound_port(), c.access.token.empty() ? "" : "?token=...",
                    o.target.c_str(), o.machine.c_str());
        std::printf("state         %s\n", c.state_dir.c_str());
        if (c.mqtt) {
            std::printf("mqtt          %s as pathstream/%s/, jobs from pathstream/queue/%s\n",
                        c.mqtt->url.text().c_str(), c.mqtt->name.c_str(), c.mqtt->kind.c_str());
        }
        std::fflush(stdout);
        ::signal(SIGPIPE, SIG_IGN);
        std::thread watcher([&] {
            while (!g_stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
            server.stop();
        });
        server.run();
        g_stop.store(true);
        watcher.join();
        std::printf("pathstream serve: stopped\n");
    }
    if (temporary) {
        std::error_code ignored;
        fs::remove_all(c.state_dir, ignored);
    }
    return status;
}

}  // namespace pathstream::host
