// Target URLs: what parses, what it means, and the exact message for each kind of mistake.
#include <catch2/catch.hpp>

#include "pathstream/hal/modbus_target.hpp"

using pathstream::hal::ModbusTarget;
using pathstream::hal::parse_modbus_target;

TEST_CASE("TCP target URLs", "[modbus][target]") {
    const ModbusTarget t = parse_modbus_target("modbus-tcp://127.0.0.1:5020?unit=7");
    CHECK(t.transport == ModbusTarget::Transport::kTcp);
    CHECK(t.host == "127.0.0.1");
    CHECK(t.port == 5020);
    CHECK(t.unit == 7);

    const ModbusTarget d = parse_modbus_target("modbus-tcp://plc.local");
    CHECK(d.host == "plc.local");
    CHECK(d.port == 502);
    CHECK(d.unit == 1);

    const ModbusTarget v6 = parse_modbus_target("modbus-tcp://[::1]:1502/?unit=255");
    CHECK(v6.host == "::1");
    CHECK(v6.port == 1502);
    CHECK(v6.unit == 255);
    CHECK(to_string(v6) == "modbus-tcp://[::1]:1502?unit=255");
}

TEST_CASE("RTU target URLs", "[modbus][target]") {
    const ModbusTarget t = parse_modbus_target(
        "modbus-rtu:///dev/ttyUSB0?baud=115200&parity=n&unit=1&data_bits=8&stop_bits=2");
    CHECK(t.transport == ModbusTarget::Transport::kRtu);
    CHECK(t.serial.device == "/dev/ttyUSB0");
    CHECK(t.serial.baud == 115200);
    CHECK(t.serial.parity == 'N');
    CHECK(t.serial.stop_bits == 2);
    CHECK(t.unit == 1);

    const ModbusTarget d = parse_modbus_target("modbus-rtu:///dev/pts/3");
    CHECK(d.serial.baud == 19200);  // the serial-line spec's defaults: 19200 8E1
    CHECK(d.serial.parity == 'E');
    CHECK(d.serial.data_bits == 8);
    CHECK(d.serial.stop_bits == 1);
    CHECK(to_string(d) ==
          "modbus-rtu:///dev/pts/3?baud=19200&parity=E&data_bits=8&stop_bits=1&unit=1");
    CHECK(to_string(parse_modbus_target(to_string(t))) == to_string(t));
}

TEST_CASE("bad target URLs say what is wrong", "[modbus][target]") {
    const auto message = [](const char* url) {
        try {
            parse_modbus_target(url);
        } catch (const std::invalid_argument& e) {
            return std::string(e.what());
        }
        return std::string("(accepted)");
    };
    CHECK(message("x") ==
          "bad target URL 'x': unknown scheme (want modbus-tcp:// or modbus-rtu://)");
    CHECK(message("modbus-tcp://") == "bad target URL 'modbus-tcp://': missing host");
    CHECK(message("modbus-tcp://h:") == "bad target URL 'modbus-tcp://h:': empty port after ':'");
    CHECK(message("modbus-tcp://h:99999") ==
          "bad target URL 'modbus-tcp://h:99999': port '99999' is not a number in 1..65535");
    CHECK(message("modbus-tcp://h:50x") ==
          "bad target URL 'modbus-tcp://h:50x': port '50x' is not a number in 1..65535");
    CHECK(message("modbus-tcp://h/dev") ==
          "bad target URL 'modbus-tcp://h/dev': a TCP target has no path (got '/dev')");
    CHECK(message("modbus-tcp://h?unit=256") ==
          "bad target URL 'modbus-tcp://h?unit=256': unit '256' is not a number in 0..255");
    CHECK(message("modbus-tcp://h?baud=9600") ==
          "bad target URL 'modbus-tcp://h?baud=9600': unknown parameter 'baud' (want unit)");
    CHECK(message("modbus-tcp://h?unit=1&unit=2") ==
          "bad target URL 'modbus-tcp://h?unit=1&unit=2': parameter 'unit' given twice");
    CHECK(message("modbus-tcp://h?unit") ==
          "bad target URL 'modbus-tcp://h?unit': query parameter 'unit' has no value (want "
          "name=value)");
    CHECK(message("modbus-rtu://") == "bad target URL 'modbus-rtu://': missing serial device path");
    CHECK(message("modbus-rtu://dev/ttyS0") ==
          "bad target URL 'modbus-rtu://dev/ttyS0': the serial device must be an absolute path "
          "(modbus-rtu:///dev/...), got 'dev/ttyS0'");
    CHECK(message("modbus-rtu:///dev/ttyS0?parity=X") ==
          "bad target URL 'modbus-rtu:///dev/ttyS0?parity=X': parity 'X' is not N, E or O");
    CHECK(
        message("modbus-rtu:///dev/ttyS0?baud=12345") ==
        "bad target URL 'modbus-rtu:///dev/ttyS0?baud=12345': baud '12345' is not a standard rate "
        "(e.g. 9600, 19200, 115200)");
    CHECK(
        message("modbus-rtu:///dev/ttyS0?unit=248") ==
        "bad target URL 'modbus-rtu:///dev/ttyS0?unit=248': unit '248' is not a number in 0..247");
    CHECK(message("modbus-rtu:///dev/ttyS0?data_bits=9") ==
          "bad target URL 'modbus-rtu:///dev/ttyS0?data_bits=9': data_bits '9' is not a number in "
          "5..8");
    CHECK(message("modbus-rtu:///dev/ttyS0?stop=1") ==
          "bad target URL 'modbus-rtu:///dev/ttyS0?stop=1': unknown parameter 'stop' (want unit, "
          "baud, "
          "parity, data_bits, stop_bits)");
    CHECK(message("modbus-rtu:///dev/ttyS0?unit=-1") ==
          "bad target URL 'modbus-rtu:///dev/ttyS0?unit=-1': unit '-1' is not a number in 0..247");
    CHECK(message("modbus-rtu:///dev/ttyS0?&unit=1") ==
          "bad target URL 'modbus-rtu:///dev/ttyS0?&unit=1': empty query parameter");
}
