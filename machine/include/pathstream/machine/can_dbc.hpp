// The DBC description of the native CAN protocol, generated from its one declaration
// (device/can_protocol.hpp). docs/pathstream.dbc is this for node 1; a test compares them.
#pragma once

#include <cstdint>
#include <string>

namespace pathstream::host {

/// The DBC file text for node `node` (1..127): every message and signal of the protocol.
std::string can_dbc(std::uint8_t node);

}  // namespace pathstream::host
