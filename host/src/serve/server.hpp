// `pathstream serve`: one page and a small HTTP API that load, place, preview, simulate and
// stream a drawing and steer the machine, with live updates as server-sent events
// (docs/serve.md).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "access.hpp"
#include "child_process.hpp"
#include "event_hub.hpp"
#include "http_types.hpp"
#include "job_desk.hpp"
#include "mqtt_bridge.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host::serve {

class HttpServer;

/// Everything the server is started with; read-only once it runs.
struct ServerConfig {
    std::string listen_host = "127.0.0.1";
    unsigned port = 8080;  ///< 0: any free port (bound_port() says which)
    AccessPolicy access;
    std::string machine_file;  ///< absolute path of the machine profile
    std::string target;        ///< the device's URL, for stream and ctl
    std::string state_dir;     ///< absolute; the uploaded drawing and the job journal live here
    std::string executable;    ///< this program, whose stream, sim and ctl commands run the jobs
    double events_rate = 10;   ///< stream --events-rate: progress updates per second
    double status_hz = 10;     ///< device status reads per second
    std::size_t max_upload_bytes = 16u << 20;
    HttpLimits limits;             ///< body_bytes comes from max_upload_bytes
    double plan_timeout_s = 60;    ///< a preview's or run's planning is stopped after this
    double max_motion_s = 86400;   ///< a job estimated to move longer is refused before planning
    std::optional<MqttLink> mqtt;  ///< serve --mqtt: report to and take commands from a broker
};

/// The HTTP server and what runs behind it: a device status poller thread, at most one job
/// (a `stream` or `sim` child) with its reader thread, and the event hub the pages listen to.
class Server {
public:
    Server(ServerConfig config, MachineProfile machine);
    ~Server();
    Server(const Server&) = delete;
    Server& operator=(const Server&) = delete;

    /// Binds the listening socket. Throws std::runtime_error when the address cannot be bound.
    void bind();
    /// The port bound (after bind()).
    unsigned bound_port() const { return bound_port_; }
    /// With ServerConfig::mqtt: connects to the broker and starts the bridge (after bind(),
    /// before run()). Throws MqttError when the broker cannot be reached or refuses.
    void start_mqtt();
    /// Serves until stop(); starts the status poller. Blocks; call once.
    void run();
    /// Ends run(): a job still streaming is asked to hold (its journal can resume it), the
    /// pages' event streams end. Any thread, not a signal handler.
    void stop();

private:
    struct Reply;
    void routes();
    Reply upload(const std::string& name, const std::string& body, const nlohmann::json& options,
                 const CancelToken& cancel);
    Reply preview(const nlohmann::json& options, const CancelToken& cancel);
    /// Streams the drawing as placed by `options`; `previewed_hash` (when not empty) is the
    /// drawing_hash of the preview the page shows, refused when another drawing is loaded.
    Reply run_job(const nlohmann::json& options, const std::string& previewed_hash,
                  const CancelToken& cancel);
    /// Cancels the plan that was newest until now: `cancel` is the newest.
    void claim_planning(const CancelToken& cancel);
    std::string drawing_hash() const;
    Reply simulate(const nlohmann::json& options, const CancelToken& cancel);
    Reply resume();
    Reply last_preview() const;
    /// Plans the drawing with the page's options: the preview with `paper` and `options`,
    /// kept as the last preview (cleared when planning throws, which it passes on).
    nlohmann::ordered_json placed_preview(const nlohmann::json& options, const CancelToken& cancel);
    void remember_whole_job(const std::string& job_start_line);
    nlohmann::ordered_json whole_job_ticks() const;
    Reply control(const nlohmann::json& request);
    nlohmann::ordered_json state() const;
    std::vector<std::string> arguments(const nlohmann::json& options) const;
    nlohmann::ordered_json plan_preview(const std::vector<std::string>& args,
                                        const CancelToken& cancel);
    bool start_child(const std::string& kind, std::vector<std::string> argv,
                     const nlohmann::ordered_json& whole_ticks = nullptr);
    bool job_running() const;
    void poll_device();
    std::string drawing_file() const;
    std::string clean_message(std::string message) const;

    ServerConfig config_;
    MachineProfile machine_;
    std::unique_ptr<HttpServer> http_;
    unsigned bound_port_ = 0;
    EventHub hub_;
    std::unique_ptr<JobDesk> desk_;  ///< before mqtt_: the bridge uses it until destroyed
    std::unique_ptr<MqttBridge> mqtt_;
    std::atomic<bool> stopping_{false};
    std::thread poller_;

    mutable std::mutex device_mutex_;  ///< the poller writes, the handlers read
    std::vector<double> rest_mm_;      ///< the device's last position read; empty: none yet

    mutable std::mutex drawing_mutex_;
    std::string drawing_name_;  ///< the stored drawing's file name; empty: none
    std::string drawing_hash_;  ///< content_hash of its bytes
    std::mutex gate_;  ///< upload, preview, run and simulate one at a time: a run streams what it
                       ///< previewed
    std::mutex newest_plan_mutex_;
    CancelToken newest_plan_;  ///< the plan running or waiting last: a newer one cancels it
    mutable std::mutex preview_mutex_;
    nlohmann::ordered_json last_preview_;  ///< the last preview answered; null: none

    mutable std::mutex job_mutex_;
    std::unique_ptr<ChildProcess> job_;
    std::thread job_thread_;
    std::string job_kind_;
    std::atomic<bool> job_running_{false};
    /// Stop asked for: the job's hold event brings the second signal (two sent at once
    /// would merge into one, a hold).
    std::atomic<bool> stop_requested_{false};
};

}  // namespace pathstream::host::serve
