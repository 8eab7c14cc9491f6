// Job messages from the broker's queue: a checked job or std::invalid_argument; a job that is
// read writes back (passed on by a busy machine) to a message that reads as the same job.
#include <stdexcept>

#include "fuzz_support.hpp"
#include "serve/job_message.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace pathstream::host::serve;
    const std::string payload = pathstream::fuzz::text_of(data, size);
    JobMessage job;
    try {
        job = parse_job_message(payload, 4096);
    } catch (const std::invalid_argument&) {
        return 0;
    }
    if (job.drawing.size() > 4096) pathstream::fuzz::violated("a drawing over the limit read");
    const JobMessage back = parse_job_message(job_message_text(job), 4096);
    if (back.id != job.id || back.file != job.file || back.drawing != job.drawing ||
        back.options != job.options || back.bounces != job.bounces)
        pathstream::fuzz::violated("a job does not read back as itself");
    return 0;
}
