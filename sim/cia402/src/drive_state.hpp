// The simulated drive's state, shared by its source files (not a public header).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "pathstream/hal/can_bus.hpp"
#include "pathstream/machine/cia402_protocol.hpp"
#include "pathstream/sim/cia402_drive.hpp"
#include "pathstream/sim/plant.hpp"

namespace pathstream::sim {

namespace cia = host::cia402;

struct DrivePdo {
    std::uint32_t cob_id = cia::kPdoInvalid;
    std::uint8_t type = 255;
    std::uint8_t count = 0;
    std::uint32_t map[8] = {};
    bool valid() const { return (cob_id & cia::kPdoInvalid) == 0; }
    unsigned bytes() const {
        unsigned bits = 0;
        for (unsigned i = 0; i < count; ++i) bits += map[i] & 0xFF;
        return bits / 8;
    }
};

struct SimulatedCia402Drive::State {
    State(hal::CanBus& b, const Cia402DriveOptions& o) : bus(b), options(o) {}

    hal::CanBus& bus;
    Cia402DriveOptions options;
    std::uint64_t now = 0;

    // Communication (reset by NMT reset communication).
    cia::NmtState nmt = cia::NmtState::kBootUp;
    bool boot_pending = true;  // send the boot-up message at the next poll
    std::uint16_t heartbeat_ms = 0;
    std::uint64_t next_heartbeat = 0;
    bool heartbeat_enabled = true;
    DrivePdo rpdo1, rpdo2, tpdo1, tpdo2;
    std::uint32_t sync_count = 0;  // for TPDO transmission types 2..240

    // Application (reset by NMT reset node or power-up).
    cia::DriveState ds = cia::DriveState::kSwitchOnDisabled;
    std::uint16_t controlword = 0;
    std::int8_t mode = 0;
    std::uint8_t ip_value = 0;
    std::int8_t ip_index = -3;
    std::int32_t target = 0;
    std::int32_t velocity_offset = 0;  // 0x60B1, LSB/s
    std::int16_t torque_offset = 0;    // 0x60B2, per mille
    // What synchronous RPDOs carried since the last SYNC, applied at the next one.
    std::uint16_t pending_cw = 0;
    std::int32_t pending_target = 0;
    std::int32_t pending_velocity_offset = 0;
    std::int16_t pending_torque_offset = 0;
    bool pending = false;  // an RPDO1 (the target's PDO) arrived since the last SYNC
    bool have_pending_cw = false;
    bool have_pending_target = false;
    bool have_pending_velocity_offset = false;
    bool have_pending_torque_offset = false;
    std::uint32_t fe_window;
    std::uint32_t qs_decel;
    std::uint16_t error_code = 0;
    bool jammed = false;

    // The axis: plant in LSB, rebuilt when the cycle changes.
    std::unique_ptr<ServoAxis> plant;
    double plant_period = 0;
    double demand = 0;     // position demand, LSB
    double last_step = 0;  // demand change of the last cycle, LSB (quick stop starts from it)
    double position = 0;   // plant position, LSB (kept here so a rebuilt plant starts from it)

    // Records.
    std::vector<std::int32_t> applied;
    double max_fe = 0;
    std::uint64_t syncs = 0, stale = 0, rpdos = 0;
    std::uint16_t last_emcy = 0;
    bool length_emcy_sent = false;

    // drive.cpp
    void send(const hal::CanFrame& f) { (void)bus.send(f); }
    void handle(const hal::CanFrame& f);
    void on_nmt(std::uint8_t command);
    void on_sync();
    void on_rpdo(const DrivePdo& p, const hal::CanFrame& f);
    void apply_pending();
    void send_tpdo(const DrivePdo& p);
    void emcy(std::uint16_t code);
    void fault(std::uint16_t code);
    void reset_communication();
    double period_seconds() const;
    std::uint16_t statusword() const;
    std::int32_t actual() const;
    // object_dictionary.cpp
    void on_sdo(const hal::CanFrame& f);
    std::uint32_t od_read(std::uint16_t index, std::uint8_t sub, std::uint32_t& value,
                          std::uint8_t& size) const;
    std::uint32_t od_write(std::uint16_t index, std::uint8_t sub, std::uint32_t value,
                           std::uint8_t size);
    // state_machine.cpp
    void apply_controlword(std::uint16_t cw);
};

}  // namespace pathstream::sim
