// Texts and the statusword table of cia402_protocol.hpp.
#include <cstdio>
#include <string>

#include "pathstream/machine/cia402_protocol.hpp"

namespace pathstream::host::cia402 {
namespace {

std::string hex(std::uint32_t v, int digits) {
    char b[16];
    std::snprintf(b, sizeof b, "0x%0*X", digits, v);
    return b;
}

}  // namespace

std::string sdo_abort_text(std::uint32_t code) {
    const char* t = nullptr;
    switch (code) {
        case 0x05030000:
            t = "toggle bit not alternated";
            break;
        case kAbortTimeout:
            t = "SDO protocol timed out";
            break;
        case kAbortCommand:
            t = "client/server command specifier not valid or unknown";
            break;
        case 0x05040005:
            t = "out of memory";
            break;
        case kAbortUnsupportedAccess:
            t = "unsupported access to an object";
            break;
        case kAbortWriteOnly:
            t = "attempt to read a write only object";
            break;
        case kAbortReadOnly:
            t = "attempt to write a read only object";
            break;
        case kAbortNoObject:
            t = "object does not exist in the object dictionary";
            break;
        case kAbortNotMappable:
            t = "object cannot be mapped to the PDO";
            break;
        case kAbortPdoLength:
            t = "the number and length of the objects to be mapped would exceed the PDO length";
            break;
        case 0x06040043:
            t = "general parameter incompatibility";
            break;
        case 0x06040047:
            t = "general internal incompatibility in the device";
            break;
        case 0x06060000:
            t = "access failed due to a hardware error";
            break;
        case kAbortLength:
            t = "data type does not match, length of service parameter does not match";
            break;
        case 0x06070012:
            t = "data type does not match, length of service parameter too high";
            break;
        case 0x06070013:
            t = "data type does not match, length of service parameter too low";
            break;
        case kAbortNoSubindex:
            t = "sub-index does not exist";
            break;
        case kAbortValueRange:
            t = "invalid value for parameter (download only)";
            break;
        case 0x06090031:
            t = "value of parameter written too high";
            break;
        case 0x06090032:
            t = "value of parameter written too low";
            break;
        case 0x06090036:
            t = "maximum value is less than minimum value";
            break;
        case kAbortGeneral:
            t = "general error";
            break;
        case 0x08000020:
            t = "data cannot be transferred or stored to the application";
            break;
        case 0x08000021:
            t = "data cannot be transferred or stored to the application because of local control";
            break;
        case kAbortDeviceState:
            t = "data cannot be transferred or stored to the application because of the present "
                "device state";
            break;
        case 0x08000023:
            t = "object dictionary dynamic generation fails or no object dictionary is present";
            break;
        default:
            break;
    }
    return std::string(t != nullptr ? t : "unknown abort code") + " (" + hex(code, 8) + ")";
}

DriveState decode_statusword(std::uint16_t sw) {
    if ((sw & 0x4F) == 0x00) return DriveState::kNotReadyToSwitchOn;
    if ((sw & 0x4F) == 0x40) return DriveState::kSwitchOnDisabled;
    if ((sw & 0x6F) == 0x21) return DriveState::kReadyToSwitchOn;
    if ((sw & 0x6F) == 0x23) return DriveState::kSwitchedOn;
    if ((sw & 0x6F) == 0x27) return DriveState::kOperationEnabled;
    if ((sw & 0x6F) == 0x07) return DriveState::kQuickStopActive;
    if ((sw & 0x4F) == 0x0F) return DriveState::kFaultReactionActive;
    if ((sw & 0x4F) == 0x08) return DriveState::kFault;
    return DriveState::kUnknown;
}

std::uint16_t statusword_bits(DriveState state) {
    switch (state) {
        case DriveState::kNotReadyToSwitchOn:
            return 0x0000;
        case DriveState::kSwitchOnDisabled:
            return 0x0040;
        case DriveState::kReadyToSwitchOn:
            return 0x0031;
        case DriveState::kSwitchedOn:
            return 0x0033;
        case DriveState::kOperationEnabled:
            return 0x0037;
        case DriveState::kQuickStopActive:
            return 0x0017;
        case DriveState::kFaultReactionActive:
            return 0x001F;
        case DriveState::kFault:
            return 0x0008;
        case DriveState::kUnknown:
            break;
    }
    return 0x0000;
}

const char* drive_state_name(DriveState state) {
    switch (state) {
        case DriveState::kNotReadyToSwitchOn:
            return "not ready to switch on";
        case DriveState::kSwitchOnDisabled:
            return "switch on disabled";
        case DriveState::kReadyToSwitchOn:
            return "ready to switch on";
        case DriveState::kSwitchedOn:
            return "switched on";
        case DriveState::kOperationEnabled:
            return "operation enabled";
        case DriveState::kQuickStopActive:
            return "quick stop active";
        case DriveState::kFaultReactionActive:
            return "fault reaction active";
        case DriveState::kFault:
            return "fault";
        case DriveState::kUnknown:
            break;
    }
    return "unknown state";
}

std::string emcy_text(std::uint16_t code) {
    const char* t = nullptr;
    switch (code) {
        case kEmcyNoError:
            t = "error reset or no error";
            break;
        case kEmcyFollowingError:
            t = "following error too large";
            break;
        case kEmcyPdoLength:
            t = "PDO not processed due to length error";
            break;
        case kEmcyHeartbeat:
            t = "life guard or heartbeat error";
            break;
        case 0x8110:
            t = "CAN overrun (objects lost)";
            break;
        case 0x8140:
            t = "recovered from bus off";
            break;
        default:
            break;
    }
    if (t == nullptr) {
        switch (code >> 12) {
            case 0x1:
                t = "generic error";
                break;
            case 0x2:
                t = "current";
                break;
            case 0x3:
                t = "voltage";
                break;
            case 0x4:
                t = "temperature";
                break;
            case 0x5:
                t = "device hardware";
                break;
            case 0x6:
                t = "device software";
                break;
            case 0x7:
                t = "additional modules";
                break;
            case 0x8:
                t = "monitoring / communication";
                break;
            case 0x9:
                t = "external error";
                break;
            case 0xF:
                t = "additional functions / device specific";
                break;
            default:
                t = "unknown error";
                break;
        }
    }
    return std::string(t) + " (" + hex(code, 4) + ")";
}

}  // namespace pathstream::host::cia402
