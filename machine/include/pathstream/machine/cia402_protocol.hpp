// CANopen (CiA 301) and CiA 402 constants shared by the host's CSP master and the simulated
// drive: COB-IDs, NMT, SDO command bytes, the object dictionary entries pathstream uses, the
// controlword commands and the statusword decoding (docs/cia402.md).
#pragma once

#include <cstdint>
#include <string>

namespace pathstream::host::cia402 {

// COB-IDs (pre-defined connection set): function code + node id for the per-node ones.
inline constexpr std::uint32_t kNmtId = 0x000;
inline constexpr std::uint32_t kSyncId = 0x080;
inline constexpr std::uint32_t kEmcyBase = 0x080;
inline constexpr std::uint32_t kTpdo1Base = 0x180;
inline constexpr std::uint32_t kRpdo1Base = 0x200;
inline constexpr std::uint32_t kTpdo2Base = 0x280;
inline constexpr std::uint32_t kRpdo2Base = 0x300;
inline constexpr std::uint32_t kSdoResponseBase = 0x580;  ///< server (drive) -> client
inline constexpr std::uint32_t kSdoRequestBase = 0x600;   ///< client (master) -> server
inline constexpr std::uint32_t kHeartbeatBase = 0x700;
/// Bit 31 of a PDO COB-ID entry: the PDO does not exist (disabled).
inline constexpr std::uint32_t kPdoInvalid = 0x80000000u;

/// NMT command specifiers (first byte of the NMT frame; second byte: node, 0 = all).
enum class NmtCommand : std::uint8_t {
    kStart = 0x01,
    kStop = 0x02,
    kEnterPreOperational = 0x80,
    kResetNode = 0x81,
    kResetCommunication = 0x82,
};

/// NMT states as a heartbeat reports them (0x00: the boot-up message).
enum class NmtState : std::uint8_t {
    kBootUp = 0x00,
    kStopped = 0x04,
    kOperational = 0x05,
    kPreOperational = 0x7F,
};

// SDO command bytes (expedited transfers only: every object pathstream uses fits 4 bytes).
inline constexpr std::uint8_t kSdoDownloadRequest =
    0x20;  ///< | (4 - n) << 2 | 0x03 (expedited, size)
inline constexpr std::uint8_t kSdoDownloadResponse = 0x60;
inline constexpr std::uint8_t kSdoUploadRequest = 0x40;
inline constexpr std::uint8_t kSdoUploadResponse =
    0x40;  ///< | (4 - n) << 2 | 0x03, or 0x42 (no size)
inline constexpr std::uint8_t kSdoAbort = 0x80;

// SDO abort codes (CiA 301 table 22) the drive raises and the master explains.
inline constexpr std::uint32_t kAbortTimeout = 0x05040000;
inline constexpr std::uint32_t kAbortCommand = 0x05040001;
inline constexpr std::uint32_t kAbortUnsupportedAccess = 0x06010000;
inline constexpr std::uint32_t kAbortWriteOnly = 0x06010001;
inline constexpr std::uint32_t kAbortReadOnly = 0x06010002;
inline constexpr std::uint32_t kAbortNoObject = 0x06020000;
inline constexpr std::uint32_t kAbortNotMappable = 0x06040041;
inline constexpr std::uint32_t kAbortPdoLength = 0x06040042;
inline constexpr std::uint32_t kAbortLength = 0x06070010;
inline constexpr std::uint32_t kAbortNoSubindex = 0x06090011;
inline constexpr std::uint32_t kAbortValueRange = 0x06090030;
inline constexpr std::uint32_t kAbortGeneral = 0x08000000;
inline constexpr std::uint32_t kAbortDeviceState = 0x08000022;

/// "object does not exist in the object dictionary" etc.; unknown codes get a generic text.
std::string sdo_abort_text(std::uint32_t code);

// Object dictionary entries (index; sub-index in the comment where it matters).
inline constexpr std::uint16_t kDeviceType = 0x1000;          ///< u32, low 16 bits 402 for a drive
inline constexpr std::uint16_t kErrorRegister = 0x1001;       ///< u8
inline constexpr std::uint16_t kHeartbeatProducer = 0x1017;   ///< u16 ms, 0 = off
inline constexpr std::uint16_t kRpdo1Communication = 0x1400;  ///< sub 1 COB-ID u32, sub 2 type u8
inline constexpr std::uint16_t kRpdo2Communication = 0x1401;
inline constexpr std::uint16_t kRpdo1Mapping = 0x1600;  ///< sub 0 count u8, sub 1..8 u32
inline constexpr std::uint16_t kRpdo2Mapping = 0x1601;
inline constexpr std::uint16_t kTpdo1Communication = 0x1800;
inline constexpr std::uint16_t kTpdo2Communication = 0x1801;
inline constexpr std::uint16_t kTpdo1Mapping = 0x1A00;
inline constexpr std::uint16_t kTpdo2Mapping = 0x1A01;
inline constexpr std::uint16_t kErrorCode = 0x603F;              ///< u16, last EMCY code
inline constexpr std::uint16_t kControlword = 0x6040;            ///< u16
inline constexpr std::uint16_t kStatusword = 0x6041;             ///< u16
inline constexpr std::uint16_t kModesOfOperation = 0x6060;       ///< i8
inline constexpr std::uint16_t kModesDisplay = 0x6061;           ///< i8
inline constexpr std::uint16_t kPositionDemand = 0x6062;         ///< i32, what the drive applies
inline constexpr std::uint16_t kPositionActual = 0x6064;         ///< i32
inline constexpr std::uint16_t kFollowingErrorWindow = 0x6065;   ///< u32 (inc)
inline constexpr std::uint16_t kTargetPosition = 0x607A;         ///< i32
inline constexpr std::uint16_t kQuickStopDeceleration = 0x6085;  ///< u32 (inc/s^2)
/// i32, velocity units (here position units per second), added to the velocity loop in CSP.
inline constexpr std::uint16_t kVelocityOffset = 0x60B1;
/// i16, per mille of the rated torque, added to the torque loop in CSP.
inline constexpr std::uint16_t kTorqueOffset = 0x60B2;
inline constexpr std::uint16_t kInterpolationPeriod =
    0x60C2;  ///< sub 1 u8 value, sub 2 i8 index (10^index s)

inline constexpr std::uint32_t kDeviceProfile402 = 402;
inline constexpr std::int8_t kModeCsp = 8;
inline constexpr std::uint8_t kTransmissionEverySync = 1;

/// A PDO mapping entry: index << 16 | sub << 8 | length in bits.
constexpr std::uint32_t pdo_mapping(std::uint16_t index, std::uint8_t sub, std::uint8_t bits) {
    return static_cast<std::uint32_t>(index) << 16 | static_cast<std::uint32_t>(sub) << 8 | bits;
}

// Controlword commands (CiA 402 table 31).
inline constexpr std::uint16_t kCwDisableVoltage = 0x0000;
inline constexpr std::uint16_t kCwQuickStop = 0x0002;
inline constexpr std::uint16_t kCwShutdown = 0x0006;
inline constexpr std::uint16_t kCwSwitchOn = 0x0007;  ///< also "disable operation"
inline constexpr std::uint16_t kCwEnableOperation = 0x000F;
inline constexpr std::uint16_t kCwFaultReset = 0x0080;  ///< acts on the rising edge of bit 7

/// The drive's power state machine states (CiA 402 figure 5).
enum class DriveState : std::uint8_t {
    kNotReadyToSwitchOn,
    kSwitchOnDisabled,
    kReadyToSwitchOn,
    kSwitchedOn,
    kOperationEnabled,
    kQuickStopActive,
    kFaultReactionActive,
    kFault,
    kUnknown,  ///< a statusword that matches no row of the table
};

/// Decodes a statusword with the mask/value table (0x4F/0x00 not ready, 0x4F/0x40 switch on
/// disabled, 0x6F/0x21 ready, 0x6F/0x23 switched on, 0x6F/0x27 operation enabled, 0x6F/0x07
/// quick stop active, 0x4F/0x0F fault reaction active, 0x4F/0x08 fault).
DriveState decode_statusword(std::uint16_t statusword);

/// The statusword bits 0-6 of `state` (bit 4 voltage enabled and bit 5 quick stop set as a
/// healthy drive reports them); the drive ORs in the other bits.
std::uint16_t statusword_bits(DriveState state);

/// "operation enabled", "fault", ...
const char* drive_state_name(DriveState state);

// Emergency error codes (CiA 301 / CiA 402) pathstream raises or explains.
inline constexpr std::uint16_t kEmcyNoError = 0x0000;
inline constexpr std::uint16_t kEmcyGeneric = 0x1000;
inline constexpr std::uint16_t kEmcyDeviceHardware = 0x5000;
inline constexpr std::uint16_t kEmcyPdoLength = 0x8210;
inline constexpr std::uint16_t kEmcyHeartbeat = 0x8130;
inline constexpr std::uint16_t kEmcyFollowingError = 0x8611;

/// Text for an EMCY error code, by its exact value or its class (high byte); e.g.
/// "following error too large (0x8611)".
std::string emcy_text(std::uint16_t code);

}  // namespace pathstream::host::cia402
