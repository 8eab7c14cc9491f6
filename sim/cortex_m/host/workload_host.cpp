// Host build of the shared Cortex-M workload (workload/workload.hpp): prints the same summary
// and checksum lines as the bare-metal images, which ctest compares.
#include <cinttypes>
#include <cstdio>

#include "workload.hpp"

int main() {
    const pathstream::workload::Summary s = pathstream::workload::run();
    std::printf("workload ticks=%" PRIu32 " accepted=%" PRIu32 " rejected=%" PRIu32
                " horner=%" PRIu32 " mismatches=%" PRIu32 "\n",
                s.ticks, s.spans_accepted, s.spans_rejected, s.horner_evaluations, s.mismatches);
    std::printf("checksum=%016" PRIx64 "\n", s.checksum);
    return s.mismatches == 0 ? 0 : 1;
}
