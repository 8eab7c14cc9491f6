// The machine functions (spindle, its direction, mist, flood) on the coils of a Modbus I/O
// module, as a profile's "output_coils" maps them (docs/gpio.md, "Output coils"): the device is
// the module's client. CoilWriter writes from the calling thread; OutputCoilThread gives it a
// thread of its own, so that the tick only publishes a byte and a slow or dead module never
// delays a tick. A write the module does not confirm stops the machine (kOutputFailed).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pathstream/device/device_state.hpp"
#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/hal/modbus_client.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::linux_device {

/// One machine function's coil.
struct OutputCoil {
    const char* function = "";  ///< the profile's key: "spindle", "spindle_reverse", ...
    std::uint8_t bit = 0;       ///< its span output bit (kOutputSpindle, ...)
    std::uint16_t address = 0;  ///< coil address on the module
};

/// The coils `config` maps, by address. Allocates; host context.
std::vector<OutputCoil> output_coil_list(const host::OutputCoilsConfig& config);

/// The client settings the device writes coils with: 500 ms response and byte timeouts, two
/// tries (a coil write is idempotent, so a retry is safe): a dead module is found within about
/// a second.
hal::ModbusClientOptions output_coil_client_options();

/// Writes the machine outputs to a module's coils. Not thread-safe: one thread (the caller's)
/// owns it; every call blocks for the module's answers, at most the client's timeouts and
/// retries.
class CoilWriter {
public:
    /// Connects to config.target. Throws hal::ModbusError (kConnectFailed) naming the target,
    /// std::invalid_argument for a config that maps no coil or a bad target.
    explicit CoilWriter(const host::OutputCoilsConfig& config,
                        const hal::ModbusClientOptions& options = output_coil_client_options());

    /// Makes the module's coils say `outputs` (the machine bits; the others are ignored):
    /// writes the coils whose function changed since the last confirmed write, or every
    /// mapped coil while the module's state is unknown (before the first write, after a
    /// failure). Mapped coils at consecutive addresses go in one FC15 write; otherwise one FC5
    /// per coil: those turning off first (the spindle's first), then those turning on (the
    /// spindle's last), so a VFD has its direction before it runs. Throws hal::ModbusError
    /// whose message names the target and each function and coil of the write that failed;
    /// the module's state is unknown after it.
    void apply(std::uint8_t outputs);

    /// Makes the module's state unknown: the next apply() writes every mapped coil (at exit,
    /// whatever the module was told before, or after it was switched off and on).
    void forget() { known_ = false; }

    /// The outputs the module confirmed last, valid while known().
    std::uint8_t written() const { return written_; }
    /// False before the first write and after a failed one.
    bool known() const { return known_; }
    /// The module's canonical URL.
    std::string target() const;
    /// "spindle=0 flood=3": the mapping, for the log.
    std::string mapping() const;
    /// Write transactions confirmed so far.
    std::uint64_t transactions() const { return client_.counters().transactions; }

private:
    void write_group(const std::vector<const OutputCoil*>& group, std::uint8_t outputs);
    void write_one(const OutputCoil& coil, bool on);
    /// Throws `e` again, its message naming the target, then `what` the write switched.
    [[noreturn]] void fail(const hal::ModbusError& e, const std::string& what) const;

    hal::ModbusClient client_;
    std::vector<OutputCoil> coils_;  // by address
    std::uint8_t mapped_ = 0;        // the bits that have a coil
    std::uint8_t written_ = 0;
    bool known_ = false;
};

/// A CoilWriter on a thread of its own. The thread that ticks the device publishes the
/// outputs after every tick (publish, after_tick); the writer thread takes the latest value
/// whole and writes what changed, so values published while a write is under way collapse
/// into the newest. Shared state: the published byte (written by the ticking thread only),
/// the failure count (written by the writer only), both atomics; the failure's text under a
/// mutex that the ticking thread takes only once a failure is counted.
class OutputCoilThread {
public:
    /// Takes `writer`, writes every mapped coil off (throws hal::ModbusError as apply() does,
    /// with no thread started), then starts the writer thread.
    explicit OutputCoilThread(CoilWriter writer);
    /// stop(), its failure ignored.
    ~OutputCoilThread();
    OutputCoilThread(const OutputCoilThread&) = delete;
    OutputCoilThread& operator=(const OutputCoilThread&) = delete;

    /// The machine outputs that are on now (device::machine_outputs_on). Never waits for the
    /// module: an atomic store, and a wake-up of the writer only when the value changed.
    /// The ticking thread only.
    void publish(std::uint8_t outputs);

    /// True when writes failed since the last call, with the last one's message ("<target>:
    /// cannot switch spindle (coil 0) on: ..."). The ticking thread only; no lock unless a
    /// failure was counted.
    bool take_failure(std::string& message);

    /// After every tick of `motion` (a MotionDevice or an AnyMotionDevice; the thread that
    /// ticks it): publishes device::machine_outputs_on(state, outputs) and, when a write failed
    /// since the last call, raises FaultCode::kOutputFailed on the device, which stops the
    /// machine at its next tick. Returns the failure's message for the log, "" when none.
    template <typename Device>
    std::string after_tick(Device& motion) {
        publish(device::machine_outputs_on(motion.state(), motion.outputs()));
        std::string message;
        if (!take_failure(message)) return message;
        motion.raise_fault(device::FaultCode::kOutputFailed);
        return message;
    }

    /// Writes confirmed by the writer thread so far (the coils written off at start are not
    /// counted). Any thread.
    std::uint32_t writes() const { return writes_.load(std::memory_order_acquire); }
    /// Failed writes so far. Any thread.
    std::uint32_t failures() const { return failures_.load(std::memory_order_acquire); }

    /// Ends the writer thread after the write under way, then writes every mapped coil off
    /// from the calling thread. Returns "" or the failure's message. Idempotent (a second
    /// call writes nothing). The ticking thread.
    std::string stop();

    /// The module's canonical URL and the mapping, for the log.
    const std::string& target() const { return target_; }
    const std::string& mapping() const { return mapping_; }

private:
    static constexpr std::uint32_t kStop = 1u << 8;

    void run();

    CoilWriter writer_;  // the writer thread's while it runs, then stop()'s
    std::string target_, mapping_;
    std::atomic<std::uint32_t> wanted_{0};  // outputs | kStop: the ticking thread writes
    std::uint32_t published_ = 0;           // the ticking thread's copy of wanted_
    std::atomic<std::uint32_t> writes_{0};
    std::atomic<std::uint32_t> failures_{0};  // the writer thread writes
    std::uint32_t failures_seen_ = 0;         // the ticking thread's
    std::mutex mutex_;                        // wake-ups and failure_text_
    std::condition_variable wake_;
    std::string failure_text_;
    bool stopped_ = false;
    std::thread thread_;
};

}  // namespace pathstream::linux_device
