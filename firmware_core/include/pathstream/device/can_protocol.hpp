// The native pathstream CAN protocol (CAN 2.0A, classic frames), declared once for both ends:
// the device (can_node.hpp) decodes what the host encodes and the other way round, and the DBC
// file docs/pathstream.dbc is generated from kMessages below (a test compares it byte for
// byte). docs/can.md has the prose.
//
// Every signal is byte aligned and little-endian (DBC "@1", Intel), except the span data
// frames' payload, which is the wire-span byte stream (wire_span.hpp, big-endian) cut into
// 7-byte pieces. Identifiers: function base + node id (1..127), like CANopen's COB-IDs.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pathstream/span.hpp"

namespace pathstream::device::can {

/// 2: job ends (wire flag kWireJobEnd, status frame D), continuity checked at every join.
/// 3: home and pen commands (CommandArgs 8, 9), the homing and pen flags (status A), each
/// axis's homing state (status E).
/// 4: programmed pauses (wire flag kWirePause) and the paused flag (status A bit 6).
/// 5: machine-function outputs in the spans (kOutputMachineMask, kept through holds; undefined
/// output bits refused) and the spindle flag (status A bit 7).
inline constexpr std::uint8_t kProtocolVersion = 5;
inline constexpr std::uint8_t kMinNode = 1;
inline constexpr std::uint8_t kMaxNode = 127;

/// Function bases (low 7 bits: node id). Lower identifiers win arbitration: commands first,
/// then the device's answers (flow control must not wait behind span data), then the bulk.
inline constexpr std::uint32_t kCommandBase = 0x100;    ///< host -> device
inline constexpr std::uint32_t kAckBase = 0x180;        ///< device -> host
inline constexpr std::uint32_t kStatusABase = 0x200;    ///< device -> host
inline constexpr std::uint32_t kStatusBBase = 0x280;    ///< device -> host
inline constexpr std::uint32_t kStatusCBase = 0x300;    ///< device -> host
inline constexpr std::uint32_t kConfigBase = 0x380;     ///< host -> device
inline constexpr std::uint32_t kSpanStartBase = 0x400;  ///< host -> device
inline constexpr std::uint32_t kSpanDataBase = 0x480;   ///< host -> device
inline constexpr std::uint32_t kStatusDBase = 0x500;  ///< device -> host (jobs; added in version 2)
/// device -> host, one frame per axis (position and queue epoch; added in version 2)
inline constexpr std::uint32_t kStatusEBase = 0x580;
/// host -> device: a command with arguments: 6 jog, 7 set position (added in version 2),
/// 8 home, 9 pen (version 3)
inline constexpr std::uint32_t kCommandArgsBase = 0x600;

/// Identifier of function `base` for node `node`. Constant, any context.
constexpr std::uint32_t can_id(std::uint32_t base, std::uint8_t node) {
    return base + node;
}
/// Function base of identifier `id` (0 when `id` is not one of ours). Constant.
constexpr std::uint32_t function_of(std::uint32_t id) {
    const std::uint32_t base = id & ~0x7Fu;
    return (base >= kCommandBase && base <= kCommandArgsBase && (id & 0x7Fu) != 0) ? base : 0;
}
constexpr std::uint8_t node_of(std::uint32_t id) {
    return static_cast<std::uint8_t>(id & 0x7Fu);
}

/// Command frame values: device::Command (1..5) plus a status request. Any other value is
/// passed to the device, which refuses it (ack result kUnknownCommand).
inline constexpr std::uint8_t kCommandStatusRequest = 0x10;  ///< answer with status A, B, C, D

/// Ack kinds (what is acknowledged).
inline constexpr std::uint8_t kAckSpans = 1;
inline constexpr std::uint8_t kAckCommand = 2;
inline constexpr std::uint8_t kAckConfig = 3;

/// Ack results: a core Status value (status.hpp, 0 = kOk), or one of these protocol codes.
inline constexpr std::uint8_t kResultIncomplete =
    0x80;  ///< a span data frame was lost: send the batch again
inline constexpr std::uint8_t kResultBadFrame =
    0x81;  ///< wrong length or unknown configuration item
inline constexpr std::uint8_t kResultTooLong = 0x82;  ///< batch payload over kMaxTransferBytes

/// Span transfer: one span-start frame, then ceil(length / 7) data frames indexed 0, 1, ...
inline constexpr std::size_t kDataBytesPerFrame = 7;
inline constexpr std::size_t kMaxDataFrames = 256;
inline constexpr std::size_t kMaxTransferBytes = kDataBytesPerFrame * kMaxDataFrames;  // 1792

/// Status A flags.
inline constexpr std::uint8_t kFlagConfigured = 1u << 0;
inline constexpr std::uint8_t kFlagHeldByUnderrun = 1u << 1;
inline constexpr std::uint8_t kFlagBusProblem = 1u
                                                << 2;  ///< the device saw error-passive or bus-off
/// The last tick was a tick of the device's own stop or re-entry move (holding without it: at
/// rest).
inline constexpr std::uint8_t kFlagOwnMove = 1u << 3;
/// A homing run goes on (the device's own moves, axis by axis).
inline constexpr std::uint8_t kFlagHoming = 1u << 4;
/// The pen output is down (the status's outputs; while idle only by the operator's pen).
inline constexpr std::uint8_t kFlagPenDown = 1u << 5;
/// Holding at a programmed pause (a span with kWirePause ended); resume continues the job.
inline constexpr std::uint8_t kFlagPaused = 1u << 6;
/// The spindle output is on (kOutputSpindle in the status's outputs); coolant is not reported.
inline constexpr std::uint8_t kFlagSpindle = 1u << 7;

/// Configuration items: 0 tick rate, 1 + 2a axis a's max velocity, 2 + 2a its acceleration,
/// 18 + 2a its travel min, 19 + 2a its travel max (LSB, signed; optional: without them the
/// whole position range), kConfigItemPenDown the
/// pen-down delay in ticks. The pen-down delay is sent last: the device applies the set when
/// it arrives after all the others (item 0 starts a set).
inline constexpr std::uint8_t kConfigItemPenDown = 17;
constexpr std::uint8_t config_item_velocity(unsigned axis) {
    return static_cast<std::uint8_t>(1 + 2 * axis);
}
constexpr std::uint8_t config_item_acceleration(unsigned axis) {
    return static_cast<std::uint8_t>(2 + 2 * axis);
}
constexpr std::uint8_t config_item_min_position(unsigned axis) {
    return static_cast<std::uint8_t>(18 + 2 * axis);
}
constexpr std::uint8_t config_item_max_position(unsigned axis) {
    return static_cast<std::uint8_t>(19 + 2 * axis);
}
/// Item 34 + a: axis a's max jerk (units of 100 LSB/s^3; optional: without it, or 0, no jerk
/// limit).
constexpr std::uint8_t config_item_jerk(unsigned axis) {
    return static_cast<std::uint8_t>(34 + axis);
}

/// A frame as the protocol sees it (the HAL's CanFrame without the flags it never uses).
struct Frame {
    std::uint32_t id = 0;
    std::uint8_t length = 0;
    std::uint8_t data[8] = {};
};

// ---- the declaration: every message and signal ------------------------------------------

/// One byte-aligned little-endian signal.
struct Signal {
    const char* name;
    std::uint8_t byte;   ///< first byte
    std::uint8_t bytes;  ///< 1, 2, 4 or 7 (the raw data payload)
    bool is_signed;
    const char* unit;
    const char* comment;
    std::int16_t mux = -1;  ///< multiplexed: present when the message's multiplexor equals this;
                            ///< -2: the multiplexor
    /// DBC value table (`VAL_`): "0 \"idle\" 1 \"running\"", or nullptr. Host side only.
    const char* values = nullptr;
};

// Value tables of the DBC, one per enumeration the frames carry.
inline constexpr const char* kCommandValues =
    "1 \"start\" 2 \"hold\" 3 \"resume\" 4 \"stop\" 5 \"reset\" 16 \"status request\"";
inline constexpr const char* kStateValues =
    "0 \"idle\" 1 \"running\" 2 \"holding\" 3 \"stopping\" 4 \"fault\" 5 \"e-stop\"";
inline constexpr const char* kAckKindValues = "1 \"span batch\" 2 \"command\" 3 \"configuration\"";
inline constexpr const char* kResultValues =
    "0 \"ok\" 1 \"tick count out of range\" 2 \"control value out of range\" 3 \"curve leaves the "
    "position range\" "
    "4 \"per-tick difference out of range\" 5 \"unknown basis\" 6 \"tick outside span\" 7 \"span "
    "queue full\" "
    "8 \"discontinuous span\" 9 \"velocity limit\" 10 \"acceleration limit\" 11 \"bad limits\" "
    "12 \"not configured\" 13 \"bad sequence\" 14 \"bad batch\" 15 \"wrong state\" 16 \"stop too "
    "long\" "
    "17 \"nothing to resume\" 18 \"velocity step\" 19 \"job end moving\" 20 \"unknown command\" "
    "21 \"no homing switch\" 22 \"outside travel\" 23 \"pause moving\" 24 \"jerk limit\" "
    "25 \"acceleration step\" "
    "128 \"incomplete transfer\" 129 \"bad frame\" 130 \"too long\"";
inline constexpr const char* kFaultValues =
    "0 \"none\" 1 \"external\" 2 \"stop failed\" 3 \"re-entry failed\" 4 \"output failed\" "
    "256 \"limit axis 0 negative\" 257 \"limit axis 0 positive\" 258 \"limit axis 1 negative\" "
    "259 \"limit axis 1 positive\" 260 \"limit axis 2 negative\" 261 \"limit axis 2 positive\" "
    "262 \"limit axis 3 negative\" 263 \"limit axis 3 positive\" 264 \"limit axis 4 negative\" "
    "265 \"limit axis 4 positive\" 266 \"limit axis 5 negative\" 267 \"limit axis 5 positive\" "
    "268 \"limit axis 6 negative\" 269 \"limit axis 6 positive\" 270 \"limit axis 7 negative\" "
    "271 \"limit axis 7 positive\"";

inline constexpr const char* kHomingValues =
    "0 \"not homed\" 1 \"homing\" 2 \"homed\" 3 \"failed\"";
inline constexpr const char* kHomingErrorValues =
    "0 \"none\" 1 \"bad configuration\" 2 \"device refused\" 3 \"switch not found\" "
    "4 \"switch stuck\" 5 \"latch not found\" 6 \"interrupted\"";
inline constexpr const char* kCommandArgsValues =
    "6 \"jog\" 7 \"set position\" 8 \"home\" 9 \"pen\"";

struct Message {
    const char* name;
    std::uint32_t base;
    std::uint8_t length;  ///< DLC (data frames: up to; the last one may be shorter)
    bool from_device;
    const char* comment;
    const Signal* signals;
    std::uint8_t signal_count;
};

// Signal indices below are used by the encoders: keep each table's order.
inline constexpr Signal kCommandSignals[] = {
    {"Command", 0, 1, false, "", "1 start, 2 hold, 3 resume, 4 stop, 5 reset, 16 status request",
     -1, kCommandValues},
};
inline constexpr Signal kAckSignals[] = {
    {"Kind", 0, 1, false, "", "1 span batch, 2 command, 3 configuration", -1, kAckKindValues},
    {"Result", 1, 1, false, "",
     "core Status (0 ok, 7 queue full, 13 bad sequence, ...), 128 incomplete transfer, 129 bad "
     "frame, 130 too long",
     -1, kResultValues},
    {"Sequence", 2, 4, false, "", "span batch: its first sequence number; command: the command"},
    {"FreeSlots", 6, 1, false, "span", "free span slots after this"},
    {"State", 7, 1, false, "", "0 idle, 1 running, 2 holding, 3 stopping, 4 fault, 5 e-stop", -1,
     kStateValues},
};
inline constexpr Signal kStatusASignals[] = {
    {"State", 0, 1, false, "", "0 idle, 1 running, 2 holding, 3 stopping, 4 fault, 5 e-stop", -1,
     kStateValues},
    {"Flags", 1, 1, false, "",
     "bit 0 configured, bit 1 held by underrun, bit 2 bus problem seen, bit 3 own stop or re-entry "
     "move, bit 4 homing, "
     "bit 5 pen down, bit 6 paused at a programmed pause, bit 7 spindle on"},
    {"FreeSlots", 2, 1, false, "span", "free span slots"},
    {"Queued", 3, 1, false, "span", "spans queued"},
    {"FaultCode", 4, 2, false, "",
     "0 none, 1 external, 2 stop failed, 3 re-entry failed, 4 output failed, 0x01xx limit "
     "switch",
     -1, kFaultValues},
    {"Underruns", 6, 2, false, "", "controlled stops because the queue ran dry"},
};
inline constexpr Signal kStatusBSignals[] = {
    {"LastAccepted", 0, 4, false, "", "sequence number of the last span accepted"},
    {"LastCompleted", 4, 4, false, "", "sequence number of the last span executed to its end"},
};
inline constexpr Signal kStatusCSignals[] = {
    {"TicksExecuted", 0, 4, false, "tick", "path ticks executed (low 32 bits)"},
    {"Duplicates", 4, 2, false, "", "span batches acknowledged as retries"},
    {"Axes", 6, 1, false, "", "axis count"},
    {"Version", 7, 1, false, "", "protocol version"},
};
inline constexpr Signal kStatusDSignals[] = {
    {"FinishedJob", 0, 4, false, "",
     "id (first span's sequence number) of the last job run to its end, 0 none"},
    {"FinishedJobTicks", 4, 4, false, "tick", "path ticks that job executed (low 32 bits)"},
};
inline constexpr Signal kStatusESignals[] = {
    {"Axis", 0, 1, false, "", "axis index, 0 .. axes - 1"},
    {"Position", 1, 4, true, "LSB", "setpoint the last tick output on that axis"},
    {"Epoch", 5, 2, false, "", "queue epoch (low 16 bits): advanced by every queue drop"},
    {"Homing", 7, 1, false, "",
     "low nibble: 0 not homed, 1 homing, 2 homed, 3 failed; high nibble: why it failed"},
};
inline constexpr Signal kConfigSignals[] = {
    {"Item", 0, 1, false, "",
     "0 tick rate, 1+2a axis a max velocity, 2+2a axis a max acceleration, 18+2a / 19+2a axis a "
     "travel min / max, "
     "34+a axis a max jerk, 17 pen-down delay (last)",
     -2},
    {"Axes", 1, 1, false, "", "axis count (must match the device)"},
    {"TickRate", 2, 4, false, "Hz", "device tick rate", 0},
    {"MaxVelocity0", 2, 4, false, "LSB/s", "axis 0", 1},
    {"MaxAcceleration0", 2, 4, false, "LSB/s^2", "axis 0", 2},
    {"MaxVelocity1", 2, 4, false, "LSB/s", "axis 1", 3},
    {"MaxAcceleration1", 2, 4, false, "LSB/s^2", "axis 1", 4},
    {"MaxVelocity2", 2, 4, false, "LSB/s", "axis 2", 5},
    {"MaxAcceleration2", 2, 4, false, "LSB/s^2", "axis 2", 6},
    {"MaxVelocity3", 2, 4, false, "LSB/s", "axis 3", 7},
    {"MaxAcceleration3", 2, 4, false, "LSB/s^2", "axis 3", 8},
    {"MaxVelocity4", 2, 4, false, "LSB/s", "axis 4", 9},
    {"MaxAcceleration4", 2, 4, false, "LSB/s^2", "axis 4", 10},
    {"MaxVelocity5", 2, 4, false, "LSB/s", "axis 5", 11},
    {"MaxAcceleration5", 2, 4, false, "LSB/s^2", "axis 5", 12},
    {"MaxVelocity6", 2, 4, false, "LSB/s", "axis 6", 13},
    {"MaxAcceleration6", 2, 4, false, "LSB/s^2", "axis 6", 14},
    {"MaxVelocity7", 2, 4, false, "LSB/s", "axis 7", 15},
    {"MaxAcceleration7", 2, 4, false, "LSB/s^2", "axis 7", 16},
    {"PenDownDelay", 2, 4, false, "tick", "pen-down delay, 0..65535; the last item of a set",
     kConfigItemPenDown},
    {"MinPosition0", 2, 4, true, "LSB", "axis 0 travel min", 18},
    {"MaxPosition0", 2, 4, true, "LSB", "axis 0 travel max", 19},
    {"MinPosition1", 2, 4, true, "LSB", "axis 1 travel min", 20},
    {"MaxPosition1", 2, 4, true, "LSB", "axis 1 travel max", 21},
    {"MinPosition2", 2, 4, true, "LSB", "axis 2 travel min", 22},
    {"MaxPosition2", 2, 4, true, "LSB", "axis 2 travel max", 23},
    {"MinPosition3", 2, 4, true, "LSB", "axis 3 travel min", 24},
    {"MaxPosition3", 2, 4, true, "LSB", "axis 3 travel max", 25},
    {"MinPosition4", 2, 4, true, "LSB", "axis 4 travel min", 26},
    {"MaxPosition4", 2, 4, true, "LSB", "axis 4 travel max", 27},
    {"MinPosition5", 2, 4, true, "LSB", "axis 5 travel min", 28},
    {"MaxPosition5", 2, 4, true, "LSB", "axis 5 travel max", 29},
    {"MinPosition6", 2, 4, true, "LSB", "axis 6 travel min", 30},
    {"MaxPosition6", 2, 4, true, "LSB", "axis 6 travel max", 31},
    {"MinPosition7", 2, 4, true, "LSB", "axis 7 travel min", 32},
    {"MaxPosition7", 2, 4, true, "LSB", "axis 7 travel max", 33},
    {"MaxJerk0", 2, 4, false, "100 LSB/s^3", "axis 0 max jerk (0: none)", 34},
    {"MaxJerk1", 2, 4, false, "100 LSB/s^3", "axis 1 max jerk (0: none)", 35},
    {"MaxJerk2", 2, 4, false, "100 LSB/s^3", "axis 2 max jerk (0: none)", 36},
    {"MaxJerk3", 2, 4, false, "100 LSB/s^3", "axis 3 max jerk (0: none)", 37},
    {"MaxJerk4", 2, 4, false, "100 LSB/s^3", "axis 4 max jerk (0: none)", 38},
    {"MaxJerk5", 2, 4, false, "100 LSB/s^3", "axis 5 max jerk (0: none)", 39},
    {"MaxJerk6", 2, 4, false, "100 LSB/s^3", "axis 6 max jerk (0: none)", 40},
    {"MaxJerk7", 2, 4, false, "100 LSB/s^3", "axis 7 max jerk (0: none)", 41},
};
inline constexpr Signal kCommandArgsSignals[] = {
    {"Command", 0, 1, false, "", "6 jog, 7 set position, 8 home, 9 pen", -1, kCommandArgsValues},
    {"Axis", 1, 1, false, "",
     "jog, set position: axis index, 0 .. axes - 1; home: axis bit mask (0: all); pen: 0"},
    {"Value", 2, 4, true, "LSB",
     "jog: distance (signed, not 0); set position: the axis's new coordinate; pen: 1 down, 0 up; "
     "home: 0"},
    {"Feed", 6, 2, false, "per mille",
     "jog: share of the axis's max velocity, 1..1000 (0: 1000); others: 0"},
};
inline constexpr Signal kSpanStartSignals[] = {
    {"FirstSequence", 0, 4, false, "", "sequence number of the batch's first span"},
    {"Count", 4, 1, false, "span", "spans in the batch (1..64)"},
    {"Length", 5, 2, false, "byte", "payload bytes (wire spans, docs/device.md), at most 1792"},
    {"Reserved", 7, 1, false, "", "0"},
};
inline constexpr Signal kSpanDataSignals[] = {
    {"Index", 0, 1, false, "", "data frame index within the batch, from 0"},
    {"Payload", 1, 7, false, "", "next 7 payload bytes in order (the last frame may be shorter)"},
};

inline constexpr Message kMessages[] = {
    {"Command", kCommandBase, 1, false, "host -> device: a command or a status request",
     kCommandSignals, 1},
    {"Ack", kAckBase, 8, true, "device -> host: answer to a span batch, command or configuration",
     kAckSignals, 5},
    {"StatusA", kStatusABase, 8, true, "device -> host: state, flow control, faults",
     kStatusASignals, 6},
    {"StatusB", kStatusBBase, 8, true, "device -> host: span sequence numbers", kStatusBSignals, 2},
    {"StatusC", kStatusCBase, 8, true, "device -> host: progress and identity", kStatusCSignals, 4},
    {"Config", kConfigBase, 6, false,
     "host -> device: tick rate, per-axis limits and travel, and pen-down delay, one item per "
     "frame",
     kConfigSignals, 44},
    {"SpanStart", kSpanStartBase, 8, false, "host -> device: starts a span batch transfer",
     kSpanStartSignals, 4},
    {"SpanData", kSpanDataBase, 8, false, "host -> device: 7 bytes of the batch's wire spans",
     kSpanDataSignals, 2},
    {"StatusD", kStatusDBase, 8, true, "device -> host: jobs", kStatusDSignals, 2},
    {"StatusE", kStatusEBase, 8, true,
     "device -> host: one axis's position and homing, and the queue epoch", kStatusESignals, 4},
    {"CommandArgs", kCommandArgsBase, 8, false,
     "host -> device: a command with arguments (jog, set position, home, pen), answered by a "
     "command ack",
     kCommandArgsSignals, 4},
};
inline constexpr std::size_t kMessageCount = sizeof(kMessages) / sizeof(kMessages[0]);

// ---- encoding through the declaration -----------------------------------------------------

/// Writes `value`'s low `s.bytes` bytes little-endian at s.byte. Any context.
constexpr void put(Frame& f, const Signal& s, std::uint32_t value) {
    for (unsigned i = 0; i < s.bytes && i < 4; ++i) {
        f.data[s.byte + i] = static_cast<std::uint8_t>(value >> (8 * i));
    }
}
/// Reads signal `s` (up to 4 bytes) little-endian. Any context.
constexpr std::uint32_t get(const Frame& f, const Signal& s) {
    std::uint32_t v = 0;
    for (unsigned i = 0; i < s.bytes && i < 4; ++i)
        v |= static_cast<std::uint32_t>(f.data[s.byte + i]) << (8 * i);
    return v;
}

/// Answer of the device to a batch, command or configuration.
struct Ack {
    std::uint8_t kind = 0;
    std::uint8_t result = 0;
    std::uint32_t sequence = 0;
    std::uint8_t free_slots = 0;
    std::uint8_t state = 0;
};

/// Everything the status frames (A, B, C, D) carry.
struct Status3 {
    std::uint8_t state = 0, flags = 0, free_slots = 0, queued = 0;
    std::uint16_t fault_code = 0, underruns = 0;
    std::uint32_t last_accepted = 0, last_completed = 0;
    std::uint32_t ticks_executed = 0;
    std::uint16_t duplicates = 0;
    std::uint8_t axes = 0, version = 0;
    std::uint32_t finished_job = 0, finished_job_ticks = 0;
    std::int32_t position[kMaxAxes] = {};  ///< status E, per axis
    std::uint16_t epoch = 0;               ///< status E (low 16 bits)
    std::uint8_t homing[kMaxAxes] = {};    ///< status E, per axis: AxisHoming | HomingError << 4
};

/// Status frames A to D the device sends per status request; then one frame E per axis.
inline constexpr std::size_t kStatusFrames = 4;

struct SpanStart {
    std::uint32_t first_sequence = 0;
    std::uint8_t count = 0;
    std::uint16_t length = 0;
};

constexpr Frame encode_command(std::uint8_t node, std::uint8_t command) {
    Frame f{can_id(kCommandBase, node), 1, {}};
    put(f, kCommandSignals[0], command);
    return f;
}

/// A command with arguments (kCommandArgsBase): jog (6), set position (7), home (8), pen (9).
struct CommandArgs {
    std::uint8_t command = 0;
    std::uint8_t axis = 0;
    std::int32_t value = 0;
    std::uint16_t feed = 0;
};
constexpr Frame encode_command_args(std::uint8_t node, const CommandArgs& c) {
    Frame f{can_id(kCommandArgsBase, node), 8, {}};
    put(f, kCommandArgsSignals[0], c.command);
    put(f, kCommandArgsSignals[1], c.axis);
    put(f, kCommandArgsSignals[2], static_cast<std::uint32_t>(c.value));
    put(f, kCommandArgsSignals[3], c.feed);
    return f;
}
constexpr bool decode_command_args(const Frame& f, CommandArgs& c) {
    if (f.length != 8) return false;
    c.command = static_cast<std::uint8_t>(get(f, kCommandArgsSignals[0]));
    c.axis = static_cast<std::uint8_t>(get(f, kCommandArgsSignals[1]));
    c.value = static_cast<std::int32_t>(get(f, kCommandArgsSignals[2]));
    c.feed = static_cast<std::uint16_t>(get(f, kCommandArgsSignals[3]));
    return true;
}

constexpr Frame encode_ack(std::uint8_t node, const Ack& a) {
    Frame f{can_id(kAckBase, node), 8, {}};
    put(f, kAckSignals[0], a.kind);
    put(f, kAckSignals[1], a.result);
    put(f, kAckSignals[2], a.sequence);
    put(f, kAckSignals[3], a.free_slots);
    put(f, kAckSignals[4], a.state);
    return f;
}
constexpr bool decode_ack(const Frame& f, Ack& a) {
    if (f.length != 8) return false;
    a.kind = static_cast<std::uint8_t>(get(f, kAckSignals[0]));
    a.result = static_cast<std::uint8_t>(get(f, kAckSignals[1]));
    a.sequence = get(f, kAckSignals[2]);
    a.free_slots = static_cast<std::uint8_t>(get(f, kAckSignals[3]));
    a.state = static_cast<std::uint8_t>(get(f, kAckSignals[4]));
    return true;
}

/// The status frames, A, B, C, D.
constexpr void encode_status(std::uint8_t node, const Status3& s, Frame (&out)[kStatusFrames]) {
    Frame a{can_id(kStatusABase, node), 8, {}};
    put(a, kStatusASignals[0], s.state);
    put(a, kStatusASignals[1], s.flags);
    put(a, kStatusASignals[2], s.free_slots);
    put(a, kStatusASignals[3], s.queued);
    put(a, kStatusASignals[4], s.fault_code);
    put(a, kStatusASignals[5], s.underruns);
    Frame b{can_id(kStatusBBase, node), 8, {}};
    put(b, kStatusBSignals[0], s.last_accepted);
    put(b, kStatusBSignals[1], s.last_completed);
    Frame c{can_id(kStatusCBase, node), 8, {}};
    put(c, kStatusCSignals[0], s.ticks_executed);
    put(c, kStatusCSignals[1], s.duplicates);
    put(c, kStatusCSignals[2], s.axes);
    put(c, kStatusCSignals[3], s.version);
    Frame d{can_id(kStatusDBase, node), 8, {}};
    put(d, kStatusDSignals[0], s.finished_job);
    put(d, kStatusDSignals[1], s.finished_job_ticks);
    out[0] = a;
    out[1] = b;
    out[2] = c;
    out[3] = d;
}
/// Status frame E: axis `axis`'s position, the queue epoch's low 16 bits and the axis's
/// homing byte (AxisHoming in the low nibble, HomingError in the high one).
constexpr Frame encode_status_axis(std::uint8_t node, std::uint8_t axis, std::int32_t position,
                                   std::uint32_t epoch, std::uint8_t homing = 0) {
    Frame e{can_id(kStatusEBase, node), 8, {}};
    put(e, kStatusESignals[0], axis);
    put(e, kStatusESignals[1], static_cast<std::uint32_t>(position));
    put(e, kStatusESignals[2], epoch & 0xFFFFu);
    put(e, kStatusESignals[3], homing);
    return e;
}
/// Merges one status frame (A to E) into `s`; false when `f` is none of them (or names an
/// axis beyond kMaxAxes).
constexpr bool decode_status_part(const Frame& f, Status3& s) {
    if (f.length != 8) return false;
    switch (function_of(f.id)) {
        case kStatusABase:
            s.state = static_cast<std::uint8_t>(get(f, kStatusASignals[0]));
            s.flags = static_cast<std::uint8_t>(get(f, kStatusASignals[1]));
            s.free_slots = static_cast<std::uint8_t>(get(f, kStatusASignals[2]));
            s.queued = static_cast<std::uint8_t>(get(f, kStatusASignals[3]));
            s.fault_code = static_cast<std::uint16_t>(get(f, kStatusASignals[4]));
            s.underruns = static_cast<std::uint16_t>(get(f, kStatusASignals[5]));
            return true;
        case kStatusBBase:
            s.last_accepted = get(f, kStatusBSignals[0]);
            s.last_completed = get(f, kStatusBSignals[1]);
            return true;
        case kStatusEBase: {
            const std::uint32_t axis = get(f, kStatusESignals[0]);
            if (axis >= kMaxAxes) return false;
            s.position[axis] = static_cast<std::int32_t>(get(f, kStatusESignals[1]));
            s.epoch = static_cast<std::uint16_t>(get(f, kStatusESignals[2]));
            s.homing[axis] = static_cast<std::uint8_t>(get(f, kStatusESignals[3]));
            return true;
        }
        case kStatusCBase:
            s.ticks_executed = get(f, kStatusCSignals[0]);
            s.duplicates = static_cast<std::uint16_t>(get(f, kStatusCSignals[1]));
            s.axes = static_cast<std::uint8_t>(get(f, kStatusCSignals[2]));
            s.version = static_cast<std::uint8_t>(get(f, kStatusCSignals[3]));
            return true;
        case kStatusDBase:
            s.finished_job = get(f, kStatusDSignals[0]);
            s.finished_job_ticks = get(f, kStatusDSignals[1]);
            return true;
        default:
            return false;
    }
}

/// Configuration item `item` (0: tick rate; config_item_velocity/acceleration) = `value`.
constexpr Frame encode_config(std::uint8_t node, std::uint8_t item, std::uint8_t axes,
                              std::uint32_t value) {
    Frame f{can_id(kConfigBase, node), 6, {}};
    put(f, kConfigSignals[0], item);
    put(f, kConfigSignals[1], axes);
    put(f, kConfigSignals[2], value);  // every multiplexed value sits at bytes 2..5
    return f;
}

constexpr Frame encode_span_start(std::uint8_t node, const SpanStart& s) {
    Frame f{can_id(kSpanStartBase, node), 8, {}};
    put(f, kSpanStartSignals[0], s.first_sequence);
    put(f, kSpanStartSignals[1], s.count);
    put(f, kSpanStartSignals[2], s.length);
    put(f, kSpanStartSignals[3], 0);
    return f;
}
constexpr bool decode_span_start(const Frame& f, SpanStart& s) {
    if (f.length != 8) return false;
    s.first_sequence = get(f, kSpanStartSignals[0]);
    s.count = static_cast<std::uint8_t>(get(f, kSpanStartSignals[1]));
    s.length = static_cast<std::uint16_t>(get(f, kSpanStartSignals[2]));
    return true;
}

/// Data frame `index` of a payload of `length` bytes (index < data_frames(length)).
constexpr Frame encode_span_data(std::uint8_t node, std::uint8_t index, const std::uint8_t* payload,
                                 std::size_t length) {
    Frame f{can_id(kSpanDataBase, node), 0, {}};
    const std::size_t from = static_cast<std::size_t>(index) * kDataBytesPerFrame;
    const std::size_t n = length - from < kDataBytesPerFrame ? length - from : kDataBytesPerFrame;
    put(f, kSpanDataSignals[0], index);
    for (std::size_t i = 0; i < n; ++i) f.data[kSpanDataSignals[1].byte + i] = payload[from + i];
    f.length = static_cast<std::uint8_t>(1 + n);
    return f;
}
/// Data frames a payload of `length` bytes takes.
constexpr std::size_t data_frames(std::size_t length) {
    return (length + kDataBytesPerFrame - 1) / kDataBytesPerFrame;
}

/// Bits of a CAN 2.0A data frame with `n` data bytes on the wire: 47 + 8n without stuffing,
/// plus the worst-case stuff bits (one per 4 bits after the first of the 34 + 8n stuffed bits).
constexpr std::uint32_t frame_bits_worst_case(std::uint32_t n) {
    return 47 + 8 * n + (34 + 8 * n - 1) / 4;
}

}  // namespace pathstream::device::can
