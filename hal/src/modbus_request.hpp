// Private to the server: the request PDU parser (pathstream/hal/modbus_pdu.hpp) under the
// names the dispatch uses.
#pragma once

#include "pathstream/hal/modbus_pdu.hpp"

namespace pathstream::hal::detail {
using namespace pathstream::hal::pdu;
}  // namespace pathstream::hal::detail
