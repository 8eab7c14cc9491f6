// A CANopen CiA 402 cyclic synchronous position (CSP) master for third-party drives on a
// hal::CanBus: NMT, expedited SDO configuration, RPDO1/TPDO1 (+ RPDO2 feed-forward, + optional
// TPDO2) mapping, SYNC
// at the cycle, heartbeat consumer, EMCY, the enable state machine, and the plan played through
// the firmware core with one setpoint per cycle (docs/cia402.md).
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "pathstream/hal/can_bus.hpp"
#include "pathstream/hal/clock.hpp"
#include "pathstream/host/plan.hpp"
#include "pathstream/host/stream_types.hpp"
#include "pathstream/machine/cia402_protocol.hpp"
#include "pathstream/machine/machine.hpp"

namespace pathstream::host {

/// A CiA 402 failure the user must act on (refused SDO, missing drive, fault, lost heartbeat).
/// A StreamError, so the CLI reports it like every other link or device failure (exit 6).
class Cia402Error : public StreamError {
public:
    using StreamError::StreamError;
};

/// An SDO transfer the drive aborted (or that timed out: code kAbortTimeout).
class SdoError : public Cia402Error {
public:
    SdoError(const std::string& what, std::uint32_t code) : Cia402Error(what), code_(code) {}
    std::uint32_t code() const { return code_; }

private:
    std::uint32_t code_;
};

/// What the master sends each cycle besides the target (docs/cia402.md "Feed-forward").
enum class Cia402FeedForward : std::uint8_t {
    kNone,      ///< the target only: the drive's position loop lags by 2 zeta v / omega
    kVelocity,  ///< + velocity offset 0x60B1 (RPDO2): the exact velocity of each cycle's target
    kTorque,    ///< + torque offset 0x60B2 from the exact acceleration (needs the inertia)
};

/// "none", "velocity", "torque".
const char* cia402_feed_forward_name(Cia402FeedForward feed_forward);

/// How the master runs the drives. Times are in milliseconds of the master's clock.
struct Cia402Options {
    std::vector<std::uint8_t> nodes{1};  ///< node id (1..127) of the drive of each axis, path order
    std::uint32_t cycle_ms = 2;          ///< SYNC period; a whole number of the profile's ticks
    std::uint16_t heartbeat_ms = 100;    ///< producer time written to every drive (0x1017)
    std::uint32_t heartbeat_timeout_ms = 350;  ///< consumer: no heartbeat for this long -> stop
    std::uint32_t sdo_timeout_ms = 50;         ///< per SDO try
    unsigned sdo_attempts = 3;  ///< expedited transfers are idempotent: retried on timeout
    std::uint32_t boot_timeout_ms = 1000;    ///< wait for boot-up after reset communication
    std::uint32_t enable_timeout_ms = 500;   ///< shutdown -> switch on -> enable operation
    std::uint32_t settle_timeout_ms = 1000;  ///< after the end point: wait for the axes to arrive
    std::int32_t settle_window = 20;         ///< LSB: |actual - end point| counted as arrived
    std::int32_t start_tolerance = 50;       ///< LSB: drive position vs the plan's start
    /// Consecutive cycles without a drive's TPDO1 before the master stops (a lost SYNC or TPDO
    /// costs one; the drive's own heartbeat is the slower backstop).
    unsigned max_missed_feedback = 5;
    /// Map TPDO2 (0x280+n) = position demand value 0x6062: the master then sees, per cycle,
    /// which target the drive applied, and counts lost RPDOs exactly (4 more bytes per axis
    /// per cycle on the bus).
    bool demand_echo = false;
    /// Feed-forward sent with each target: velocity (default) removes the position loop's lag
    /// on every drive that adds 0x60B1 to its velocity loop; kNone is the target alone.
    Cia402FeedForward feed_forward = Cia402FeedForward::kVelocity;
    /// kTorque: the torque offset (per mille of rated torque) one LSB/s^2 of acceleration
    /// takes, i.e. the axis's inertia over the motor's rated torque (x 1000, per LSB/s^2).
    double torque_per_acceleration = 0;
    bool disable_at_end = true;       ///< shutdown (0x06) after the settle phase
    bool reset_communication = true;  ///< NMT reset communication before configuring
};

/// Why the master stopped commanding motion.
enum class Cia402Stop : std::uint8_t {
    kNone = 0,            ///< completed: every cycle's setpoint was sent and the axes arrived
    kDriveFault,          ///< a drive reported fault (statusword or EMCY)
    kHeartbeatLost,       ///< no heartbeat within heartbeat_timeout_ms
    kFeedbackLost,        ///< max_missed_feedback cycles without TPDO1
    kDriveLeftOperation,  ///< the drive left operation enabled / NMT operational on its own
    kStepLimit,      ///< the next target would step more than v_max x cycle (or a_max x cycle^2)
    kBusOff,         ///< the controller went bus-off or refused to send
    kSettleTimeout,  ///< the axes did not reach the end point within settle_timeout_ms
};

/// "drive fault", "heartbeat lost", ...
const char* cia402_stop_name(Cia402Stop stop);

/// What the master did.
struct Cia402Report {
    bool completed = false;
    Cia402Stop stop = Cia402Stop::kNone;
    std::string message;              ///< why it stopped, naming the node; empty when completed
    std::uint64_t cycles = 0;         ///< SYNCs sent (enable, motion, settle, stop)
    std::uint64_t motion_cycles = 0;  ///< cycles that carried a plan setpoint
    std::uint64_t total_motion_cycles = 0;  ///< what the plan needs
    std::uint64_t path_ticks = 0;           ///< plan ticks covered by the setpoints sent
    std::uint64_t frames_sent = 0;
    std::uint64_t frames_received = 0;
    std::uint64_t missed_feedback = 0;  ///< drive-cycles without TPDO1
    std::uint64_t demand_mismatches =
        0;                        ///< demand_echo: cycles whose applied target was not the one sent
    std::uint16_t emcy_code = 0;  ///< first EMCY error code seen (0: none)
    std::uint8_t emcy_node = 0;
    std::int32_t max_step = 0;                 ///< largest |target step| commanded, LSB per cycle
    std::int32_t max_lag = 0;                  ///< largest |target sent - actual reported| seen
    std::vector<std::int32_t> final_target;    ///< last target per axis
    std::vector<std::int32_t> final_position;  ///< last actual position per axis
    double wall_seconds = 0;                   ///< on the master's clock
};

/// Progress: fraction of the plan's cycles sent.
using Cia402Progress = std::function<void(double fraction)>;

/// What the master knows of one drive.
struct Cia402DriveView {
    std::uint8_t node = 0;
    cia402::NmtState nmt = cia402::NmtState::kBootUp;
    bool heartbeat_seen = false;
    std::uint64_t last_heartbeat_us = 0;
    std::uint16_t statusword = 0;
    std::int32_t position = 0;         ///< position actual value from TPDO1
    std::int32_t demand = 0;           ///< position demand value from TPDO2 (demand_echo)
    std::uint64_t feedback_cycle = 0;  ///< cycle (1-based) of the last TPDO1; 0: none yet
    std::uint64_t demand_cycle = 0;
    unsigned missed_in_row = 0;
    std::uint16_t emcy_code = 0;  ///< last EMCY error code (0: none or reset)
    bool emcy_pending = false;    ///< an EMCY with a non-zero code arrived
    cia402::DriveState state() const { return cia402::decode_statusword(statusword); }
};

/// The master. Not thread-safe: one task owns it, the bus and the clock. `clock` counts
/// microseconds (hal::LinuxClock(1e6) on Linux, a virtual clock in tests); every wait is a
/// bus receive with a timeout up to the next deadline, so the master never sleeps past a frame.
class Cia402Master {
public:
    /// Throws std::invalid_argument for bad options (no nodes, node outside 1..127, repeated
    /// node, zero cycle, torque feed-forward without a finite torque_per_acceleration > 0).
    Cia402Master(hal::CanBus& bus, hal::Clock& clock_us, Cia402Options options);

    /// NMT reset communication (if configured) and boot-up of every node, device type check
    /// (profile 402), then over SDO: mode 8 (CSP), interpolation period (cycle_ms, index -3),
    /// RPDO1 = controlword + target position on 0x200+n (synchronous), RPDO2 = velocity offset
    /// (+ torque offset) on 0x300+n with feed-forward (else disabled), TPDO1 = statusword +
    /// position actual on 0x180+n (every SYNC), TPDO2 = position demand on 0x280+n when
    /// demand_echo, heartbeat producer time; every mapping read back; then NMT start and the
    /// operational heartbeat. Throws SdoError / Cia402Error naming node and object.
    void configure();

    /// Expedited SDO download of `size` (1, 2 or 4) bytes of `value` to node:index:sub.
    /// Retries on timeout (sdo_attempts); throws SdoError with the decoded abort code.
    void sdo_download(std::uint8_t node, std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                      std::uint8_t size);
    /// Expedited SDO upload; returns the value (zero-extended) and its size in `size` if given.
    std::uint32_t sdo_upload(std::uint8_t node, std::uint16_t index, std::uint8_t sub,
                             std::uint8_t* size = nullptr);

    /// Sends an NMT command to `node` (0: all).
    void nmt(cia402::NmtCommand command, std::uint8_t node);

    /// Runs cycles holding `targets` (one per axis) while stepping every drive through
    /// shutdown -> switch on -> enable operation. Returns Cia402Stop::kNone once all are
    /// operation enabled, else why not (report().message says more). A drive in fault stops
    /// it (kDriveFault): call fault_reset() first.
    Cia402Stop enable(const std::vector<std::int32_t>& targets);

    /// Fault reset: controlword 0x00 then 0x80 (the rising edge of bit 7) until every drive
    /// leaves fault (switch on disabled). Returns true on success within enable_timeout_ms.
    bool fault_reset();

    /// Enables the drives at the plan's start, sends one core setpoint per cycle (the plan
    /// played through pathstream::SetpointStream at the profile's tick rate, every C-th setpoint
    /// with C = cycle_ms x tick_hz / 1000, and the end point), waits for the axes to settle,
    /// then disables them (disable_at_end). Checks each target against the previous ones
    /// before sending (|step| <= v_max x cycle + 1 LSB, |second difference| <= a_max x cycle^2
    /// + 2 LSB) and every cycle's feedback; on any failure it stops commanding motion (quick
    /// stop with the last target held) and returns the report with the reason. With
    /// feed-forward each target goes with the velocity of the cycle it ends (its backward
    /// difference) and, kTorque, the acceleration around that cycle (central, one cycle ahead).
    /// Throws std::invalid_argument if the plan does not fit (axes, cycle vs tick rate, a
    /// torque offset at a_max beyond 32767 per mille).
    Cia402Report run(const Plan& plan, const MachineProfile& profile,
                     const Cia402Progress& progress = {});

    const std::vector<Cia402DriveView>& drives() const { return drives_; }
    const Cia402Report& report() const { return report_; }
    const Cia402Options& options() const { return options_; }

private:
    void send(const hal::CanFrame& frame);
    void handle(const hal::CanFrame& frame);
    void wait_until(std::uint64_t deadline_us);
    /// Per axis: velocity offset (LSB/s) and torque offset (per mille) of one cycle.
    struct Offsets {
        std::vector<std::int32_t> velocity;
        std::vector<std::int16_t> torque;
    };
    /// One cycle: RPDO1 (and RPDO2 with feed-forward: `offsets`, zero when null) per drive,
    /// then SYNC, then the answers until the cycle's deadline.
    void exchange(const std::vector<std::uint16_t>& controlwords,
                  const std::vector<std::int32_t>& targets, const Offsets* offsets = nullptr);
    Cia402Stop check_health(bool moving);
    Cia402Stop stop_with(Cia402Stop why, const std::string& message);
    void quick_stop(const std::vector<std::int32_t>& hold);
    void configure_node(std::uint8_t node);
    std::uint32_t sdo_transfer(std::uint8_t node, const hal::CanFrame& request, std::uint8_t* size);
    Cia402DriveView& view(std::uint8_t node);

    hal::CanBus& bus_;
    hal::Clock& clock_;
    Cia402Options options_;
    std::vector<Cia402DriveView> drives_;
    Cia402Report report_;
    std::uint64_t cycle_ = 0;          // cycles exchanged so far
    std::uint64_t next_deadline_ = 0;  // end of the current cycle, us
    bool cycling_ = false;
    std::string send_failure_;  // set by send() while cycling; check_health() stops on it
    // SDO response being waited for (node, matched in handle()).
    std::uint8_t sdo_node_ = 0;
    bool sdo_done_ = false;
    hal::CanFrame sdo_response_{};
};

/// A parsed `can://IFACE?node=N&protocol=cia402&cycle=2ms` target.
struct Cia402Target {
    std::string interface;
    Cia402Options options;
};

/// Parses a CiA 402 target for `axes` axes. Query keys: node=N (axis a on node N + a) or
/// nodes=N1,N2,... (one per axis), protocol=cia402 (required), cycle=Kms (default 2ms),
/// heartbeat=Kms, echo=1 (demand_echo), ff=none|velocity|torque (default velocity),
/// inertia=X (torque_per_acceleration, required by ff=torque). Throws std::invalid_argument
/// with what is wrong.
Cia402Target parse_cia402_target(const std::string& url, std::size_t axes);

/// The whole job on an open bus: configure(), run(). Throws Cia402Error when run() stops
/// before completion (the report's message), after the drives were stopped.
Cia402Report stream_cia402(const Plan& plan, const MachineProfile& profile,
                           const Cia402Options& options, hal::CanBus& bus, hal::Clock& clock_us,
                           const Cia402Progress& progress = {});

}  // namespace pathstream::host

namespace pathstream::host {

/// A hal::Clock counting microseconds of std::chrono::steady_clock from its construction;
/// wait_until() sleeps. What the master runs on outside tests.
class SteadyMicrosecondClock final : public hal::Clock {
public:
    SteadyMicrosecondClock();
    std::uint64_t now() const override;
    void wait_until(std::uint64_t tick) override;

private:
    std::int64_t start_ns_;
};

/// `pathstream stream --target can://IFACE?...&protocol=cia402`: parses `target` for the
/// profile's axes, runs stream_cia402 on `bus` with a progress bar and prints the report
/// (cycles, bus frames and worst-case load, following). Returns the exit code (0); throws
/// Cia402Error (exit 6) when the drives stopped early, std::invalid_argument for a bad target.
int run_cia402_stream(const Plan& plan, const MachineProfile& profile, const std::string& target,
                      hal::CanBus& bus);

}  // namespace pathstream::host
