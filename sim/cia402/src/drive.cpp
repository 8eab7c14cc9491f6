// The simulated drive's bus side: NMT, heartbeat, RPDO/TPDO, EMCY, and the CSP cycle at SYNC.
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "drive_state.hpp"

namespace pathstream::sim {

using namespace host::cia402;

namespace {

hal::CanFrame frame(std::uint32_t id, std::uint8_t length) {
    hal::CanFrame f;
    f.id = id;
    f.length = length;
    return f;
}

void put(hal::CanFrame& f, unsigned at, unsigned bytes, std::uint32_t v) {
    for (unsigned i = 0; i < bytes; ++i) f.data[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

std::uint32_t get(const hal::CanFrame& f, unsigned at, unsigned bytes) {
    std::uint32_t v = 0;
    for (unsigned i = 0; i < bytes; ++i) v |= static_cast<std::uint32_t>(f.data[at + i]) << (8 * i);
    return v;
}

}  // namespace

SimulatedCia402Drive::SimulatedCia402Drive(hal::CanBus& bus, const Cia402DriveOptions& options)
    : s_(std::make_unique<State>(bus, options)) {
    if (options.node < 1 || options.node > 127)
        throw std::invalid_argument("CiA 402 drive: node outside 1..127");
    if (!std::isfinite(options.torque_per_acceleration) || options.torque_per_acceleration < 0)
        throw std::invalid_argument(
            "CiA 402 drive: torque per acceleration must be a finite number >= 0");
    s_->fe_window = options.following_error_window;
    s_->qs_decel = options.quick_stop_deceleration;
    s_->position = s_->demand = options.start_position;
    s_->target = options.start_position;
    s_->reset_communication();
}

SimulatedCia402Drive::~SimulatedCia402Drive() = default;

void SimulatedCia402Drive::State::reset_communication() {
    heartbeat_ms = 0;
    const std::uint8_t n = options.node;
    rpdo1 = DrivePdo{};
    rpdo1.cob_id = kPdoInvalid | (kRpdo1Base + n);
    rpdo2 = DrivePdo{};
    rpdo2.cob_id = kPdoInvalid | (kRpdo2Base + n);
    tpdo1 = DrivePdo{};
    tpdo1.cob_id = kPdoInvalid | (kTpdo1Base + n);
    tpdo2 = DrivePdo{};
    tpdo2.cob_id = kPdoInvalid | (kTpdo2Base + n);
    nmt = NmtState::kBootUp;
    boot_pending = true;
    pending = have_pending_cw = have_pending_target = false;
    have_pending_velocity_offset = have_pending_torque_offset = false;
}

double SimulatedCia402Drive::State::period_seconds() const {
    if (ip_value == 0) return 0;
    return ip_value * std::pow(10.0, ip_index);
}

std::int32_t SimulatedCia402Drive::State::actual() const {
    return static_cast<std::int32_t>(std::llround(position));
}

std::uint16_t SimulatedCia402Drive::State::statusword() const {
    std::uint16_t sw = statusword_bits(ds) | 0x0200;  // bit 9 remote: the bus is in control
    if (ds == DriveState::kOperationEnabled && mode == kModeCsp)
        sw |= 0x1000;  // bit 12: follows the target
    return sw;
}

void SimulatedCia402Drive::State::emcy(std::uint16_t code) {
    hal::CanFrame f = frame(kEmcyBase + options.node, 8);
    put(f, 0, 2, code);
    f.data[2] = code != 0 ? 0x01 : 0x00;  // error register: generic error
    send(f);
    last_emcy = code;
}

void SimulatedCia402Drive::State::fault(std::uint16_t code) {
    if (ds == DriveState::kFault) return;
    // The fault reaction (power stage off, axis braked where it is) is immediate here.
    ds = DriveState::kFault;
    error_code = code;
    demand = position;
    last_step = 0;
    emcy(code);
}

void SimulatedCia402Drive::poll(std::uint64_t now_us) {
    State& s = *s_;
    s.now = now_us;
    hal::CanFrame f;
    while (s.bus.receive(f, 0)) s.handle(f);
    if (s.boot_pending) {
        // Boot-up: heartbeat frame with state 0; the node is then pre-operational.
        s.boot_pending = false;
        hal::CanFrame b = frame(kHeartbeatBase + s.options.node, 1);
        b.data[0] = 0x00;
        s.send(b);
        s.nmt = NmtState::kPreOperational;
    }
    if (s.heartbeat_ms > 0 && s.heartbeat_enabled && now_us >= s.next_heartbeat) {
        hal::CanFrame h = frame(kHeartbeatBase + s.options.node, 1);
        h.data[0] = static_cast<std::uint8_t>(s.nmt);
        s.send(h);
        s.next_heartbeat = now_us + std::uint64_t{s.heartbeat_ms} * 1000;
    }
}

std::uint64_t SimulatedCia402Drive::next_event_us() const {
    if (s_->boot_pending) return s_->now;
    if (s_->heartbeat_ms == 0 || !s_->heartbeat_enabled)
        return std::numeric_limits<std::uint64_t>::max();
    return s_->next_heartbeat;
}

void SimulatedCia402Drive::State::handle(const hal::CanFrame& f) {
    if (f.extended || f.remote) return;
    const std::uint8_t n = options.node;
    if (f.id == kNmtId) {
        if (f.length >= 2 && (f.data[1] == 0 || f.data[1] == n)) on_nmt(f.data[0]);
        return;
    }
    if (nmt == NmtState::kStopped || nmt == NmtState::kBootUp) return;  // only NMT while stopped
    if (f.id == kSdoRequestBase + n) {
        on_sdo(f);
        return;
    }
    if (nmt != NmtState::kOperational) return;  // SYNC and PDOs only when operational
    if (f.id == kSyncId) {
        on_sync();
    } else if (rpdo1.valid() && f.id == (rpdo1.cob_id & 0x7FF)) {
        on_rpdo(rpdo1, f);
    } else if (rpdo2.valid() && f.id == (rpdo2.cob_id & 0x7FF)) {
        on_rpdo(rpdo2, f);
    }
}

void SimulatedCia402Drive::State::on_nmt(std::uint8_t command) {
    switch (static_cast<NmtCommand>(command)) {
        case NmtCommand::kStart:
            nmt = NmtState::kOperational;
            break;
        case NmtCommand::kStop:
            nmt = NmtState::kStopped;
            break;
        case NmtCommand::kEnterPreOperational:
            nmt = NmtState::kPreOperational;
            break;
        case NmtCommand::kResetNode:
            ds = error_code != 0 ? DriveState::kFault : DriveState::kSwitchOnDisabled;
            mode = 0;
            ip_value = 0;
            ip_index = -3;
            fe_window = options.following_error_window;
            qs_decel = options.quick_stop_deceleration;
            velocity_offset = 0;
            torque_offset = 0;
            reset_communication();
            break;
        case NmtCommand::kResetCommunication:
            reset_communication();
            break;
        default:
            break;
    }
    // Leaving operational while enabled: a drive loses its master's commands, so it stops.
    if (nmt != NmtState::kOperational && ds == DriveState::kOperationEnabled) {
        ds = DriveState::kQuickStopActive;
    }
}

void SimulatedCia402Drive::State::on_rpdo(const DrivePdo& p, const hal::CanFrame& f) {
    if (f.length != p.bytes()) {
        if (!length_emcy_sent) emcy(kEmcyPdoLength);  // once: not a fault, the frame is dropped
        length_emcy_sent = true;
        return;
    }
    unsigned at = 0;
    for (unsigned i = 0; i < p.count; ++i) {
        const std::uint16_t index = static_cast<std::uint16_t>(p.map[i] >> 16);
        const unsigned bytes = (p.map[i] & 0xFF) / 8;
        const std::uint32_t v = get(f, at, bytes);
        at += bytes;
        if (index == kControlword) {
            pending_cw = static_cast<std::uint16_t>(v);
            have_pending_cw = true;
        } else if (index == kTargetPosition) {
            pending_target = static_cast<std::int32_t>(v);
            have_pending_target = true;
        } else if (index == kVelocityOffset) {
            pending_velocity_offset = static_cast<std::int32_t>(v);
            have_pending_velocity_offset = true;
        } else if (index == kTorqueOffset) {
            pending_torque_offset = static_cast<std::int16_t>(v);
            have_pending_torque_offset = true;
        }
    }
    ++rpdos;
    if (&p == &rpdo1) pending = true;
    if (p.type >= 254) apply_pending();  // asynchronous: applied at once
}

void SimulatedCia402Drive::State::apply_pending() {
    if (have_pending_target) target = pending_target;
    if (have_pending_velocity_offset) velocity_offset = pending_velocity_offset;
    if (have_pending_torque_offset) torque_offset = pending_torque_offset;
    if (have_pending_cw) apply_controlword(pending_cw);
    have_pending_cw = have_pending_target = false;
    have_pending_velocity_offset = have_pending_torque_offset = false;
}

void SimulatedCia402Drive::State::on_sync() {
    ++syncs;
    ++sync_count;
    // Synchronous RPDO contents take effect at the SYNC; a lost RPDO leaves the last ones.
    const bool fresh = pending;
    pending = false;
    // A drive that becomes enabled at this SYNC starts from where it is; targets count from
    // the next SYNC on.
    const bool was_enabled = ds == DriveState::kOperationEnabled;
    apply_pending();

    const double period = period_seconds() > 0 ? period_seconds() : 0.001;
    const double before = demand;
    FeedForward ff;  // only while following targets in CSP
    switch (ds) {
        case DriveState::kOperationEnabled:
            if (mode == kModeCsp && was_enabled) {
                if (!fresh) ++stale;
                demand = target;
                applied.push_back(target);
                ff.velocity = velocity_offset;
                if (options.torque_per_acceleration > 0)
                    ff.acceleration = torque_offset / options.torque_per_acceleration;
            }
            break;
        case DriveState::kQuickStopActive: {
            // Brake on the quick stop ramp from the demand's last speed, then switch on disabled.
            const double dv = qs_decel * period * period;
            double step = last_step;
            step = std::fabs(step) <= dv ? 0 : step - std::copysign(dv, step);
            demand += step;
            if (step == 0) ds = DriveState::kSwitchOnDisabled;
            break;
        }
        default:
            demand = position;
            break;  // power stage off: the demand tracks the axis
    }
    last_step = demand - before;
    const bool powered = ds == DriveState::kOperationEnabled || ds == DriveState::kQuickStopActive;
    if (powered && !jammed) {
        // (Re)built at rest where the axis is after a pause or a change of cycle: building
        // costs a matrix exponential, so not every cycle.
        if (!plant || plant_period != period) {
            plant = std::make_unique<ServoAxis>(options.servo, period, position);
            plant_period = period;
        }
        // The demand moves linearly from the last target to this one over the cycle, as a
        // drive interpolating between cycle targets runs it: the target is reached at the
        // cycle's end, and the velocity offset is the slope of that line.
        plant->step_interpolated(before, demand, ff);
        position = plant->position();
    } else {
        plant.reset();  // unpowered or jammed: the axis stands still
    }
    if (ds == DriveState::kOperationEnabled) {
        const double fe = std::fabs(demand - position);
        if (fe > max_fe) max_fe = fe;
        if (fe > fe_window) fault(kEmcyFollowingError);
    }
    if (tpdo1.valid() && tpdo1.type >= 1 && tpdo1.type <= 240 && sync_count % tpdo1.type == 0)
        send_tpdo(tpdo1);
    if (tpdo2.valid() && tpdo2.type >= 1 && tpdo2.type <= 240 && sync_count % tpdo2.type == 0)
        send_tpdo(tpdo2);
}

void SimulatedCia402Drive::State::send_tpdo(const DrivePdo& p) {
    hal::CanFrame f = frame(p.cob_id & 0x7FF, static_cast<std::uint8_t>(p.bytes()));
    unsigned at = 0;
    for (unsigned i = 0; i < p.count; ++i) {
        const std::uint16_t index = static_cast<std::uint16_t>(p.map[i] >> 16);
        const unsigned bytes = (p.map[i] & 0xFF) / 8;
        std::uint32_t v = 0;
        if (index == kStatusword) v = statusword();
        if (index == kPositionActual) v = static_cast<std::uint32_t>(actual());
        if (index == kPositionDemand)
            v = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::llround(demand)));
        put(f, at, bytes, v);
        at += bytes;
    }
    send(f);
}

void SimulatedCia402Drive::inject_fault(std::uint16_t code) {
    s_->fault(code);
}
void SimulatedCia402Drive::jam(bool jammed) {
    s_->jammed = jammed;
}
void SimulatedCia402Drive::set_heartbeat_enabled(bool enabled) {
    s_->heartbeat_enabled = enabled;
}
NmtState SimulatedCia402Drive::nmt_state() const {
    return s_->nmt;
}
DriveState SimulatedCia402Drive::state() const {
    return s_->ds;
}
std::uint16_t SimulatedCia402Drive::statusword() const {
    return s_->statusword();
}
std::int32_t SimulatedCia402Drive::position_actual() const {
    return s_->actual();
}
std::int32_t SimulatedCia402Drive::position_demand() const {
    return static_cast<std::int32_t>(std::llround(s_->demand));
}
std::int8_t SimulatedCia402Drive::mode() const {
    return s_->mode;
}
std::uint32_t SimulatedCia402Drive::interpolation_period_ms() const {
    return static_cast<std::uint32_t>(std::llround(s_->period_seconds() * 1000));
}
const std::vector<std::int32_t>& SimulatedCia402Drive::applied_targets() const {
    return s_->applied;
}
double SimulatedCia402Drive::max_following_error() const {
    return s_->max_fe;
}
std::uint64_t SimulatedCia402Drive::syncs() const {
    return s_->syncs;
}
std::uint64_t SimulatedCia402Drive::stale_syncs() const {
    return s_->stale;
}
std::int32_t SimulatedCia402Drive::velocity_offset() const {
    return s_->velocity_offset;
}
std::int16_t SimulatedCia402Drive::torque_offset() const {
    return s_->torque_offset;
}
std::uint64_t SimulatedCia402Drive::rpdos() const {
    return s_->rpdos;
}
std::uint16_t SimulatedCia402Drive::last_emcy() const {
    return s_->last_emcy;
}

}  // namespace pathstream::sim
