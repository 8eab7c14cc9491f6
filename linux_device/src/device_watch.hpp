// What the device's log says of its status and its clients: jobs starting and ending, state
// changes and faults by name, connections (rate-limited). Internal to the runtime.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

#include "pathstream/device/device_state.hpp"
#include "pathstream/hal/modbus_server.hpp"
#include "pathstream/linux_device/any_motion_device.hpp"
#include "pathstream/linux_device/device_log.hpp"
#include "pathstream/machine/device_setup.hpp"

namespace pathstream::linux_device {

// What the log follows of the device's status after every tick.
struct DeviceView {
    device::DeviceState state = device::DeviceState::kIdle;
    std::uint16_t fault_code = 0;
    std::uint32_t job = 0;  ///< job of the span in progress or last played (0: none)
    std::uint32_t finished_job = 0, finished_job_ticks = 0;
};

// A reader of `d`'s status as the log follows it.
inline std::function<DeviceView()> status_reader(const AnyMotionDevice& d) {
    return [&d] {
        return DeviceView{d.state(), d.fault_code(), d.job(), d.finished_job(),
                          d.finished_job_ticks()};
    };
}

// Logs what an operator follows: client connections, jobs starting and finishing, every state
// change and faults by name (the e-stop, fault and reset lines keep their words: tests and
// scripts look for them); a streaming host sees the same in the status block.
class DeviceWatch {
public:
    DeviceWatch(const DeviceLog& log, std::function<DeviceView()> read)
        : log_(log), read_(std::move(read)), last_(read_()), started_job_(last_.job) {}

    // After every tick: the job that ended, then the state, then the job that began.
    void after_tick(const AnyMotionDevice& d) {
        const DeviceView v = read_();
        const std::uint64_t tick = d.ticks_run();
        if (v.finished_job != last_.finished_job && v.finished_job != 0) job_end(v, tick);
        const bool new_fault = v.state == kFault && v.fault_code != last_.fault_code;
        if (v.state != last_.state || new_fault) state_change(v, tick);
        if (v.state == kRunning && v.job != 0 && v.job != started_job_) job_start(v, tick);
        last_ = v;
    }

    // After every Modbus poll: connections accepted and closed since the last one. At most
    // kConnectionLines lines in kConnectionWindow; beyond them a client that connects and
    // leaves in a loop is counted, and one line per window says how many.
    // `last`: the device stops, the counted connections are said now.
    void after_poll(const hal::ModbusServer& server, bool last = false) {
        const hal::ModbusServerCounters& c = server.counters();
        const std::uint64_t closed = c.connections_closed.load(),
                            accepted = c.connections_accepted.load();
        const auto now = std::chrono::steady_clock::now();
        if (now - window_start_ >= kConnectionWindow || last) {
            if (quiet_accepted_ + quiet_closed_ > 0) {
                log_("connections",
                     std::to_string(quiet_accepted_) + " more clients connected and " +
                         std::to_string(quiet_closed_) + " disconnected in " +
                         std::to_string(kConnectionWindow.count()) + " s (" +
                         std::to_string(open_after(accepted, closed)) + " open)",
                     {{"connected", quiet_accepted_},
                      {"disconnected", quiet_closed_},
                      {"open", open_after(accepted, closed)}});
            }
            window_start_ = now;
            window_lines_ = quiet_accepted_ = quiet_closed_ = 0;
        }
        while (accepted_ < accepted) {
            ++accepted_;
            if (window_lines_ < kConnectionLines) {
                ++window_lines_;
                log_("connect", "client connected (" + std::to_string(open()) + " open)",
                     {{"open", open()}});
            } else {
                ++quiet_accepted_;
            }
        }
        while (closed_ < closed && closed_ < accepted_) {
            ++closed_;
            if (window_lines_ < kConnectionLines) {
                ++window_lines_;
                log_("disconnect", "client disconnected (" + std::to_string(open()) + " open)",
                     {{"open", open()}});
            } else {
                ++quiet_closed_;
            }
        }
    }

private:
    static constexpr device::DeviceState kRunning = device::DeviceState::kRunning;
    static constexpr device::DeviceState kFault = device::DeviceState::kFault;
    static constexpr device::DeviceState kEstop = device::DeviceState::kEstop;
    static constexpr device::DeviceState kIdle = device::DeviceState::kIdle;

    static constexpr unsigned kConnectionLines = 20;
    static constexpr std::chrono::seconds kConnectionWindow{10};

    std::uint64_t open() const { return accepted_ - closed_; }
    static std::uint64_t open_after(std::uint64_t accepted, std::uint64_t closed) {
        return accepted > closed ? accepted - closed : 0;
    }

    void job_start(const DeviceView& v, std::uint64_t tick) {
        started_job_ = v.job;
        log_("job_start",
             "job " + std::to_string(v.job) + " started at tick " + std::to_string(tick),
             {{"job", v.job}, {"tick", tick}});
    }

    void job_end(const DeviceView& v, std::uint64_t tick) {
        log_("job_end",
             "job " + std::to_string(v.finished_job) + " finished at tick " + std::to_string(tick) +
                 ": " + std::to_string(v.finished_job_ticks) + " path ticks",
             {{"job", v.finished_job}, {"ticks", v.finished_job_ticks}, {"tick", tick}});
    }

    void state_change(const DeviceView& v, std::uint64_t tick) {
        host::EventJson fields = {{"state", host::device_state_name(v.state)},
                                  {"code", static_cast<unsigned>(v.state)},
                                  {"was", host::device_state_name(last_.state)},
                                  {"tick", tick}};
        const std::string at = " at tick " + std::to_string(tick);
        std::string text;
        if (v.state == kEstop) {
            text =
                "E-STOP" + at + ": axes held, drives disabled; release the e-stop and send reset";
        } else if (v.state == kFault) {
            fields["fault"] = host::fault_text(v.fault_code);
            fields["fault_code"] = v.fault_code;
            text = "FAULT" + at + ": " + host::fault_text(v.fault_code) +
                   "; drives disabled until reset";
        } else if (v.state == kIdle && (last_.state == kEstop || last_.state == kFault)) {
            text = "reset: idle" + at;
        } else {
            text = std::string("state ") + host::device_state_name(v.state) + " (was " +
                   host::device_state_name(last_.state) + ")" + at;
        }
        log_("state", text, fields);
    }

    const DeviceLog& log_;
    std::function<DeviceView()> read_;
    DeviceView last_;
    std::uint32_t started_job_ = 0;
    std::uint64_t accepted_ = 0, closed_ = 0;
    std::chrono::steady_clock::time_point window_start_ = std::chrono::steady_clock::now();
    unsigned window_lines_ = 0;
    std::uint64_t quiet_accepted_ = 0, quiet_closed_ = 0;
};

}  // namespace pathstream::linux_device
