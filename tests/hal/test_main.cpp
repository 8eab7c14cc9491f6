// Catch2 entry point for the hal tests (Modbus transport).
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
