// Bringing the drives up: NMT reset communication and boot-up, SDO configuration of CSP, the
// interpolation period, the PDO mapping and the heartbeat, read back, then NMT start.
#include <cstdio>
#include <string>

#include "pathstream/host/cia402_master.hpp"

namespace pathstream::host {

using namespace cia402;

namespace {

std::string hex32(std::uint32_t v) {
    char b[16];
    std::snprintf(b, sizeof b, "0x%08X", v);
    return b;
}

}  // namespace

void Cia402Master::configure() {
    cycling_ = false;
    const std::uint64_t boot_us = std::uint64_t{options_.boot_timeout_ms} * 1000;
    if (options_.reset_communication) {
        for (auto& d : drives_) {
            d.heartbeat_seen = false;
            nmt(NmtCommand::kResetCommunication, d.node);
        }
        // Boot-up (heartbeat 0x00) follows a reset: the drive is in pre-operational then.
        const std::uint64_t deadline = clock_.now() + boot_us;
        hal::CanFrame f;
        for (;;) {
            bool all = true;
            for (const auto& d : drives_) all = all && d.heartbeat_seen;
            if (all) break;
            const std::uint64_t now = clock_.now();
            if (now >= deadline) {
                for (const auto& d : drives_) {
                    if (!d.heartbeat_seen) {
                        throw Cia402Error(
                            "node " + std::to_string(d.node) + ": no boot-up message within " +
                            std::to_string(options_.boot_timeout_ms) +
                            " ms of NMT reset communication (is the drive on the bus?)");
                    }
                }
            }
            if (bus_.receive(f, static_cast<std::uint32_t>(deadline > now ? deadline - now : 0)))
                handle(f);
        }
    } else {
        for (const auto& d : drives_) nmt(NmtCommand::kEnterPreOperational, d.node);
    }
    for (const auto& d : drives_) configure_node(d.node);
    for (auto& d : drives_) {
        d.heartbeat_seen = false;
        d.emcy_pending = false;
        nmt(NmtCommand::kStart, d.node);
    }
    if (options_.heartbeat_ms == 0) return;
    // Wait for each drive's heartbeat to say operational (at most a few producer periods).
    const std::uint64_t deadline = clock_.now() + boot_us + 3ull * options_.heartbeat_ms * 1000;
    hal::CanFrame f;
    for (;;) {
        bool all = true;
        for (const auto& d : drives_)
            all = all && d.heartbeat_seen && d.nmt == NmtState::kOperational;
        if (all) return;
        const std::uint64_t now = clock_.now();
        if (now >= deadline) {
            for (const auto& d : drives_) {
                if (!(d.heartbeat_seen && d.nmt == NmtState::kOperational)) {
                    throw Cia402Error("node " + std::to_string(d.node) +
                                      ": no operational heartbeat after NMT start (heartbeat " +
                                      std::to_string(options_.heartbeat_ms) + " ms)");
                }
            }
        }
        if (bus_.receive(f, static_cast<std::uint32_t>(deadline > now ? deadline - now : 0)))
            handle(f);
    }
}

void Cia402Master::configure_node(std::uint8_t n) {
    const std::string who = "node " + std::to_string(n) + ": ";
    const std::uint32_t type = sdo_upload(n, kDeviceType, 0);
    if ((type & 0xFFFF) != kDeviceProfile402) {
        throw Cia402Error(who + "device type " + hex32(type) + " is not a CiA 402 drive (profile " +
                          std::to_string(type & 0xFFFF) + ")");
    }
    sdo_download(n, kModesOfOperation, 0, static_cast<std::uint8_t>(kModeCsp), 1);
    sdo_download(n, kInterpolationPeriod, 1, options_.cycle_ms, 1);
    sdo_download(n, kInterpolationPeriod, 2, static_cast<std::uint8_t>(std::int8_t{-3}),
                 1);  // 10^-3 s: ms

    // A PDO's mapping may change only while the PDO is disabled and its count is 0 (CiA 301).
    struct Pdo {
        std::uint16_t communication, mapping;
        std::uint32_t cob_id;
        std::uint32_t entries[2];
        std::uint8_t count;
    };
    const Pdo rpdo1{kRpdo1Communication,
                    kRpdo1Mapping,
                    kRpdo1Base + n,
                    {pdo_mapping(kControlword, 0, 16), pdo_mapping(kTargetPosition, 0, 32)},
                    2};
    // Feed-forward in a PDO of its own: controlword + target fill 6 of RPDO1's 8 bytes.
    const bool torque = options_.feed_forward == Cia402FeedForward::kTorque;
    const Pdo rpdo2{kRpdo2Communication,
                    kRpdo2Mapping,
                    kRpdo2Base + n,
                    {pdo_mapping(kVelocityOffset, 0, 32), pdo_mapping(kTorqueOffset, 0, 16)},
                    static_cast<std::uint8_t>(torque ? 2 : 1)};
    const Pdo tpdo1{kTpdo1Communication,
                    kTpdo1Mapping,
                    kTpdo1Base + n,
                    {pdo_mapping(kStatusword, 0, 16), pdo_mapping(kPositionActual, 0, 32)},
                    2};
    const Pdo tpdo2{kTpdo2Communication,
                    kTpdo2Mapping,
                    kTpdo2Base + n,
                    {pdo_mapping(kPositionDemand, 0, 32), 0},
                    1};
    auto map = [&](const Pdo& p) {
        sdo_download(n, p.communication, 1, kPdoInvalid | p.cob_id, 4);
        sdo_download(n, p.communication, 2, kTransmissionEverySync, 1);
        sdo_download(n, p.mapping, 0, 0, 1);
        for (std::uint8_t i = 0; i < p.count; ++i)
            sdo_download(n, p.mapping, static_cast<std::uint8_t>(i + 1), p.entries[i], 4);
        sdo_download(n, p.mapping, 0, p.count, 1);
        sdo_download(n, p.communication, 1, p.cob_id, 4);
        // Read back: a drive that accepted a write but maps something else must not move.
        for (std::uint8_t i = 0; i < p.count; ++i) {
            const std::uint32_t got = sdo_upload(n, p.mapping, static_cast<std::uint8_t>(i + 1));
            if (got != p.entries[i]) {
                throw Cia402Error(who + "PDO mapping readback differs at 0x" +
                                  hex32(p.mapping).substr(6) + ":" + std::to_string(i + 1) +
                                  ": wrote " + hex32(p.entries[i]) + ", read " + hex32(got));
            }
        }
    };
    // Keep a PDO the drive may map by default out of the way; a drive without one is fine.
    auto disable = [&](const Pdo& p) {
        try {
            sdo_download(n, p.communication, 1, kPdoInvalid | p.cob_id, 4);
        } catch (const SdoError& e) {
            if (e.code() != kAbortNoObject) throw;
        }
    };
    map(rpdo1);
    if (options_.feed_forward != Cia402FeedForward::kNone) {
        map(rpdo2);
    } else {
        disable(rpdo2);
    }
    map(tpdo1);
    if (options_.demand_echo) {
        map(tpdo2);
    } else {
        disable(tpdo2);
    }
    sdo_download(n, kHeartbeatProducer, 0, options_.heartbeat_ms, 2);
    const std::uint32_t mode = sdo_upload(n, kModesOfOperation, 0);
    if (mode != static_cast<std::uint8_t>(kModeCsp))
        throw Cia402Error(who + "mode of operation reads back " + std::to_string(mode) +
                          ", not 8 (CSP)");
    const std::uint32_t period = sdo_upload(n, kInterpolationPeriod, 1);
    if (period != options_.cycle_ms)
        throw Cia402Error(who + "interpolation period reads back " + std::to_string(period) +
                          " ms");
}

}  // namespace pathstream::host
