// Catch2 entry point of the host, serve and hal test programs: compiled once, linked by each.
#define CATCH_CONFIG_MAIN
#include <catch2/catch.hpp>
