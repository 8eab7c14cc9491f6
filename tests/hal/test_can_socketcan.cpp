// SocketCanBus errors that need no CAN interface: a missing interface, and (on this machine,
// whose kernel has no CAN) a non-CAN one, both named in a std::system_error. Sending and
// receiving on a real kernel: can.native_stream.vm (sim/can/vm/native_stream.sh).
#include <catch2/catch.hpp>
#include <system_error>

#include "pathstream/hal/socketcan_bus.hpp"

using namespace pathstream;

TEST_CASE("SocketCanBus names a missing interface", "[can]") {
    try {
        hal::SocketCanBus bus("nosuchcan7");
        FAIL("opened a missing interface");
    } catch (const std::system_error& e) {
        CHECK_THAT(e.what(), Catch::Contains("CAN interface nosuchcan7") &&
                                 Catch::Contains("no such interface"));
    }
}

TEST_CASE("SocketCanBus refuses a name too long for an interface", "[can]") {
    CHECK_THROWS_AS(hal::SocketCanBus("a_name_far_too_long_for_linux"), std::system_error);
}

TEST_CASE("SocketCanBus on an interface that is not CAN (lo) fails naming it", "[can]") {
    try {
        hal::SocketCanBus bus("lo");
        FAIL("bound a raw CAN socket to lo");
    } catch (const std::system_error& e) {
        CHECK_THAT(e.what(), Catch::Contains("CAN interface lo"));
    }
}
