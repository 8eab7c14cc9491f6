// Writes the DBC of the native CAN protocol for a node (default 1) to stdout:
//   pathstream_can_dbc [NODE] > docs/pathstream.dbc
// docs/pathstream.dbc is this program's output for node 1 (test_can_dbc.cpp compares).
#include <cstdlib>
#include <iostream>

#include "pathstream/machine/can_dbc.hpp"

int main(int argc, char** argv) {
    const long node = argc > 1 ? std::strtol(argv[1], nullptr, 10) : 1;
    if (node < 1 || node > 127) {
        std::cerr << "pathstream_can_dbc: node must be 1..127\n";
        return 2;
    }
    std::cout << pathstream::host::can_dbc(static_cast<std::uint8_t>(node));
    return 0;
}
