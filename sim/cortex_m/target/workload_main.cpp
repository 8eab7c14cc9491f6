// Bare-metal image: runs the shared workload (workload/workload.hpp) and prints its summary
// and checksum through semihosting. ctest compares the checksum with the host build's.
#include "semihosting.hpp"
#include "workload.hpp"

int main() {
    const pathstream::workload::Summary s = pathstream::workload::run();
    cortex_m::Line line;
    line.text("workload ticks=").dec(s.ticks).text(" accepted=").dec(s.spans_accepted)
        .text(" rejected=").dec(s.spans_rejected).text(" horner=").dec(s.horner_evaluations)
        .text(" mismatches=").dec(s.mismatches).end();
    line.text("checksum=").hex(s.checksum).end();
    return s.mismatches == 0 ? 0 : 1;
}
