// Settings of a serial line carrying Modbus RTU, shared by the server and the client.
#pragma once

#include <string>

namespace pathstream::hal {

/// A serial port and its character format. Defaults are the Modbus-over-serial spec's
/// (19200 baud, 8 data bits, even parity, 1 stop bit). Pseudo-terminals ignore the baud rate:
/// compute wire time from bytes and baud (modbus_adu.hpp), do not measure it.
struct ModbusSerialLine {
    std::string device;  ///< e.g. /dev/ttyUSB0 or a pty's /dev/pts/N
    int baud = 19200;    ///< one of the termios rates (libmodbus maps it to Bxxx)
    char parity = 'E';   ///< 'N', 'E' or 'O'
    int data_bits = 8;   ///< 5..8 (RTU wants 8)
    int stop_bits = 1;   ///< 1 or 2
};

}  // namespace pathstream::hal
