// The simulated drive's SDO server and object dictionary: expedited transfers only, with the
// abort codes a real drive gives for unknown objects, wrong sizes and writes in the wrong state.
#include <cmath>

#include "drive_state.hpp"

namespace pathstream::sim {

using namespace host::cia402;

namespace {

// Objects a PDO may carry, with their length in bits. The torque offset only with a torque
// model (Cia402DriveOptions::torque_per_acceleration): a drive that cannot act on it says so
// at configuration rather than ignoring it.
bool rpdo_mappable(std::uint32_t entry, bool torque_model) {
    return entry == pdo_mapping(kControlword, 0, 16) ||
           entry == pdo_mapping(kTargetPosition, 0, 32) ||
           entry == pdo_mapping(kVelocityOffset, 0, 32) ||
           (torque_model && entry == pdo_mapping(kTorqueOffset, 0, 16));
}
bool tpdo_mappable(std::uint32_t entry) {
    return entry == pdo_mapping(kStatusword, 0, 16) ||
           entry == pdo_mapping(kPositionActual, 0, 32) ||
           entry == pdo_mapping(kPositionDemand, 0, 32);
}

}  // namespace

void SimulatedCia402Drive::State::on_sdo(const hal::CanFrame& f) {
    if (f.length != 8) return;  // CiA 301: SDO frames always carry 8 bytes
    const std::uint8_t cs = f.data[0] >> 5;
    const std::uint16_t index = static_cast<std::uint16_t>(f.data[1] | f.data[2] << 8);
    const std::uint8_t sub = f.data[3];
    hal::CanFrame r;
    r.id = kSdoResponseBase + options.node;
    r.length = 8;
    r.data[1] = f.data[1];
    r.data[2] = f.data[2];
    r.data[3] = sub;
    std::uint32_t abort = 0;
    if (cs == 4) return;  // the client aborted: nothing is in progress here
    if (cs == 1) {
        if ((f.data[0] & 0x02) == 0) {
            abort = kAbortCommand;  // segmented download: not supported
        } else {
            const std::uint8_t size =
                (f.data[0] & 0x01) != 0 ? static_cast<std::uint8_t>(4 - ((f.data[0] >> 2) & 3)) : 0;
            std::uint32_t v = 0;
            for (unsigned i = 0; i < 4; ++i)
                v |= static_cast<std::uint32_t>(f.data[4 + i]) << (8 * i);
            abort = od_write(index, sub, v, size);
            if (abort == 0) r.data[0] = kSdoDownloadResponse;
        }
    } else if (cs == 2) {
        std::uint32_t v = 0;
        std::uint8_t size = 0;
        abort = od_read(index, sub, v, size);
        if (abort == 0) {
            r.data[0] = static_cast<std::uint8_t>(kSdoUploadResponse | (4 - size) << 2 | 0x03);
            for (unsigned i = 0; i < size; ++i)
                r.data[4 + i] = static_cast<std::uint8_t>(v >> (8 * i));
        }
    } else {
        abort = kAbortCommand;
    }
    if (abort != 0) {
        r.data[0] = kSdoAbort;
        for (unsigned i = 0; i < 4; ++i)
            r.data[4 + i] = static_cast<std::uint8_t>(abort >> (8 * i));
    }
    send(r);
}

std::uint32_t SimulatedCia402Drive::State::od_read(std::uint16_t index, std::uint8_t sub,
                                                   std::uint32_t& v, std::uint8_t& size) const {
    auto one = [&](std::uint32_t value, std::uint8_t bytes) -> std::uint32_t {
        if (sub != 0) return kAbortNoSubindex;
        v = value;
        size = bytes;
        return 0;
    };
    auto pdo_comm = [&](const DrivePdo& p) -> std::uint32_t {
        switch (sub) {
            case 0:
                v = 2;
                size = 1;
                return 0;
            case 1:
                v = p.cob_id;
                size = 4;
                return 0;
            case 2:
                v = p.type;
                size = 1;
                return 0;
            default:
                return kAbortNoSubindex;
        }
    };
    auto pdo_map = [&](const DrivePdo& p) -> std::uint32_t {
        if (sub == 0) {
            v = p.count;
            size = 1;
            return 0;
        }
        if (sub > 8) return kAbortNoSubindex;
        v = p.map[sub - 1];
        size = 4;
        return 0;
    };
    switch (index) {
        case kDeviceType:
            return one(0x00020000u | kDeviceProfile402, 4);  // servo drive, CiA 402
        case kErrorRegister:
            return one(error_code != 0 ? 1u : 0u, 1);
        case kHeartbeatProducer:
            return one(heartbeat_ms, 2);
        case kRpdo1Communication:
            return pdo_comm(rpdo1);
        case kRpdo2Communication:
            return pdo_comm(rpdo2);
        case kTpdo1Communication:
            return pdo_comm(tpdo1);
        case kTpdo2Communication:
            return pdo_comm(tpdo2);
        case kRpdo1Mapping:
            return pdo_map(rpdo1);
        case kRpdo2Mapping:
            return pdo_map(rpdo2);
        case kTpdo1Mapping:
            return pdo_map(tpdo1);
        case kTpdo2Mapping:
            return pdo_map(tpdo2);
        case kErrorCode:
            return one(error_code, 2);
        case kControlword:
            return one(controlword, 2);
        case kStatusword:
            return one(statusword(), 2);
        case kModesOfOperation:
            return one(static_cast<std::uint8_t>(mode), 1);
        case kModesDisplay:
            return one(static_cast<std::uint8_t>(mode), 1);
        case kPositionDemand:
            return one(static_cast<std::uint32_t>(static_cast<std::int32_t>(std::llround(demand))),
                       4);
        case kPositionActual:
            return one(static_cast<std::uint32_t>(actual()), 4);
        case kFollowingErrorWindow:
            return one(fe_window, 4);
        case kTargetPosition:
            return one(static_cast<std::uint32_t>(target), 4);
        case kQuickStopDeceleration:
            return one(qs_decel, 4);
        case kVelocityOffset:
            return one(static_cast<std::uint32_t>(velocity_offset), 4);
        case kTorqueOffset:
            return one(static_cast<std::uint16_t>(torque_offset), 2);
        case kInterpolationPeriod:
            switch (sub) {
                case 0:
                    v = 2;
                    size = 1;
                    return 0;
                case 1:
                    v = ip_value;
                    size = 1;
                    return 0;
                case 2:
                    v = static_cast<std::uint8_t>(ip_index);
                    size = 1;
                    return 0;
                default:
                    return kAbortNoSubindex;
            }
        default:
            return kAbortNoObject;
    }
}

std::uint32_t SimulatedCia402Drive::State::od_write(std::uint16_t index, std::uint8_t sub,
                                                    std::uint32_t v, std::uint8_t size) {
    // Size and existence first, from the read side's view of the object.
    std::uint32_t current = 0;
    std::uint8_t object_size = 0;
    if (const std::uint32_t a = od_read(index, sub, current, object_size); a != 0) return a;
    if (size != 0 && size != object_size) return kAbortLength;
    const bool operational = nmt == NmtState::kOperational;
    auto pdo_comm = [&](DrivePdo& p) -> std::uint32_t {
        if (sub == 0) return kAbortReadOnly;
        if (sub == 1) {
            // Only bit 31 (valid) may change while the PDO exists; the id needs it disabled.
            if (p.valid() && (v & kPdoInvalid) == 0 && (v & 0x7FF) != (p.cob_id & 0x7FF))
                return kAbortValueRange;
            if ((v & 0x7FF) == 0 || (v & 0x3FFFF800u) != 0) return kAbortValueRange;
            p.cob_id = v;
            return 0;
        }
        if (v > 240 && v < 254) return kAbortValueRange;
        p.type = static_cast<std::uint8_t>(v);
        return 0;
    };
    auto pdo_map = [&](DrivePdo& p, bool receive) -> std::uint32_t {
        // Mapping changes only in pre-operational, with the PDO disabled (CiA 301).
        if (operational || p.valid()) return kAbortDeviceState;
        if (sub == 0) {
            if (v > 8) return kAbortValueRange;
            unsigned bits = 0;
            for (unsigned i = 0; i < v; ++i) bits += p.map[i] & 0xFF;
            if (bits > 64) return kAbortPdoLength;
            p.count = static_cast<std::uint8_t>(v);
            return 0;
        }
        if (p.count != 0) return kAbortDeviceState;
        const bool torque_model = options.torque_per_acceleration > 0;
        if (!(receive ? rpdo_mappable(v, torque_model) : tpdo_mappable(v)))
            return kAbortNotMappable;
        p.map[sub - 1] = v;
        return 0;
    };
    switch (index) {
        case kHeartbeatProducer:
            heartbeat_ms = static_cast<std::uint16_t>(v);
            next_heartbeat = now;  // the first one at once
            return 0;
        case kRpdo1Communication:
            return pdo_comm(rpdo1);
        case kRpdo2Communication:
            return pdo_comm(rpdo2);
        case kTpdo1Communication:
            return pdo_comm(tpdo1);
        case kTpdo2Communication:
            return pdo_comm(tpdo2);
        case kRpdo1Mapping:
            return pdo_map(rpdo1, true);
        case kRpdo2Mapping:
            return pdo_map(rpdo2, true);
        case kTpdo1Mapping:
            return pdo_map(tpdo1, false);
        case kTpdo2Mapping:
            return pdo_map(tpdo2, false);
        case kControlword:
            apply_controlword(static_cast<std::uint16_t>(v));
            return 0;
        case kModesOfOperation: {
            const auto m = static_cast<std::int8_t>(v);
            if (m != 0 && m != kModeCsp) return kAbortValueRange;  // CSP is the only mode here
            if (ds == DriveState::kOperationEnabled && m != mode) return kAbortDeviceState;
            mode = m;
            return 0;
        }
        case kFollowingErrorWindow:
            fe_window = v;
            return 0;
        case kTargetPosition:
            target = static_cast<std::int32_t>(v);
            return 0;
        case kVelocityOffset:
            velocity_offset = static_cast<std::int32_t>(v);
            return 0;
        case kTorqueOffset:
            torque_offset = static_cast<std::int16_t>(v);
            return 0;
        case kQuickStopDeceleration:
            if (v == 0) return kAbortValueRange;
            qs_decel = v;
            return 0;
        case kInterpolationPeriod: {
            if (sub == 0) return kAbortReadOnly;
            if (ds == DriveState::kOperationEnabled) return kAbortDeviceState;  // not while moving
            if (sub == 1) {
                if (v == 0) return kAbortValueRange;
                ip_value = static_cast<std::uint8_t>(v);
                return 0;
            }
            const auto i = static_cast<std::int8_t>(v);
            if (i < -6 || i > 0) return kAbortValueRange;
            ip_index = i;
            return 0;
        }
        default:
            return kAbortReadOnly;  // it exists (read succeeded) but is not writable
    }
}

}  // namespace pathstream::sim
