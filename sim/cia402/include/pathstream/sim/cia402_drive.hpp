// A simulated CiA 402 servo drive on a hal::CanBus: NMT, an expedited SDO server, PDO mapping
// as configured, the power state machine, cyclic synchronous position through a second-order
// servo plant (targets interpolated linearly over the cycle, velocity and torque offsets as
// feed-forward), heartbeat and EMCY, and injectable faults (docs/cia402.md).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "pathstream/hal/can_bus.hpp"
#include "pathstream/machine/cia402_protocol.hpp"
#include "pathstream/sim/plant.hpp"

namespace pathstream::sim {

/// The drive's fixed parameters (everything the master configures is in the object dictionary).
struct Cia402DriveOptions {
    std::uint8_t node = 1;                            ///< 1..127
    std::int32_t start_position = 0;                  ///< LSB (the encoder's count at power-up)
    ServoParameters servo{100, 1.0};                  ///< the axis, in LSB (the plant is linear)
    std::uint32_t following_error_window = 5000;      ///< 0x6065 default, LSB
    std::uint32_t quick_stop_deceleration = 5000000;  ///< 0x6085 default, LSB/s^2
    /// The axis's inertia as the torque offset (0x60B2, per mille of rated torque) that one
    /// LSB/s^2 of acceleration takes: the drive turns a torque offset t into the acceleration
    /// feed-forward t / torque_per_acceleration. 0 (default): no torque model, and 0x60B2
    /// cannot be mapped into an RPDO.
    double torque_per_acceleration = 0;
};

/// One drive. Not thread-safe: one task calls poll(). Time is the caller's, in microseconds.
class SimulatedCia402Drive {
public:
    /// Powers up: NMT initialisation, then its boot-up message at the first poll().
    /// Throws std::invalid_argument for a node outside 1..127 or a torque_per_acceleration
    /// that is negative or not finite.
    SimulatedCia402Drive(hal::CanBus& bus, const Cia402DriveOptions& options);
    ~SimulatedCia402Drive();
    SimulatedCia402Drive(const SimulatedCia402Drive&) = delete;
    SimulatedCia402Drive& operator=(const SimulatedCia402Drive&) = delete;

    /// Takes every frame the bus has (without waiting) and answers it (SDO, NMT, RPDO; SYNC runs
    /// a CSP cycle and sends the TPDOs), then sends the heartbeat if due at `now_us`.
    void poll(std::uint64_t now_us);
    /// When poll() next has something to do on its own (the next heartbeat); UINT64_MAX: never.
    std::uint64_t next_event_us() const;

    // Fault injection.
    /// A commanded fault: fault state, EMCY `code` (e.g. 0x5000), power stage off.
    void inject_fault(std::uint16_t code);
    /// The axis jams: the plant stops moving, so the following error grows until the window
    /// trips (fault, EMCY 0x8611) when operation is enabled.
    void jam(bool jammed);
    /// Stops (false) or resumes the heartbeat producer without telling anyone.
    void set_heartbeat_enabled(bool enabled);

    // Observation.
    host::cia402::NmtState nmt_state() const;
    host::cia402::DriveState state() const;
    std::uint16_t statusword() const;
    std::int32_t position_actual() const;
    std::int32_t position_demand() const;
    std::int8_t mode() const;
    std::uint32_t interpolation_period_ms() const;  ///< 0x60C2 as milliseconds (0 if not set)
    /// The target applied at each SYNC while operation enabled in CSP, in order.
    const std::vector<std::int32_t>& applied_targets() const;
    std::int32_t velocity_offset() const;  ///< 0x60B1 in effect, LSB/s
    std::int16_t torque_offset() const;    ///< 0x60B2 in effect, per mille of rated torque
    /// Largest |demand - actual| while operation enabled, LSB.
    double max_following_error() const;
    std::uint64_t syncs() const;  ///< SYNCs processed while NMT operational
    std::uint64_t stale_syncs()
        const;                    ///< of which, operation enabled with no new RPDO since the last
    std::uint64_t rpdos() const;  ///< RPDO1 and RPDO2 frames accepted
    std::uint16_t last_emcy() const;  ///< last EMCY code sent (0 after a reset)

private:
    struct State;
    std::unique_ptr<State> s_;
};

}  // namespace pathstream::sim
