// The job journal and its spans file, as --resume reads them after a crash: a journal is read
// whole or refused with an InputError naming the file; a spans file read back renders to lines
// that read back to the same spans (the canonical form round-trips).
#include <stdexcept>
#include <string>

#include "fuzz_support.hpp"
#include "pathstream/host/job_journal.hpp"
#include "pathstream/machine/input_error.hpp"

namespace {

using namespace pathstream;

void check_message(const std::exception& e, const char* file) {
    if (std::string(e.what()).rfind(file, 0) != 0)
        fuzz::violated(std::string("message: ") + e.what());
}

void journal(const std::string& text) {
    try {
        const host::JobJournal j = host::parse_journal(text, "j.json");
        if (!j.replan.empty() && j.replan.front() != '{') fuzz::violated("replan is not an object");
    } catch (const host::InputError& e) {
        check_message(e, "j.json");
    } catch (const std::exception& e) {
        fuzz::violated(std::string("not an InputError: ") + e.what());
    }
}

std::string render(const host::JobSpans& job) {
    std::string text =
        "pathstream job spans 1\naxes " +
        std::to_string(job.plan.spans.empty() ? 1 : job.plan.spans.front().control.size()) +
        " spans " + std::to_string(job.plan.spans.size()) + " drawing_spans " +
        std::to_string(job.drawing_spans) + " drawing_ticks " + std::to_string(job.drawing_ticks) +
        " subpaths " + std::to_string(job.subpaths) + "\n";
    for (std::size_t i = 0; i < job.plan.spans.size(); ++i) {
        text += host::job_span_line(job.plan.spans[i], job.origin[i], job.drawing_tick[i]) + "\n";
    }
    return text;
}

void spans(const std::string& text) {
    host::JobSpans job;
    try {
        job = host::parse_job_spans(text, "j.plan", "");
    } catch (const host::InputError& e) {
        check_message(e, "j.plan");
        return;
    } catch (const std::exception& e) {
        fuzz::violated(std::string("not an InputError: ") + e.what());
    }
    std::uint64_t total = 0;
    for (const host::CoreSpan& s : job.plan.spans) {
        if (s.ticks < 1) fuzz::violated("a span of no ticks");
        total += s.ticks;
    }
    if (total != job.plan.total_ticks) fuzz::violated("total ticks");
    if (job.origin.size() != job.plan.spans.size() ||
        job.drawing_tick.size() != job.plan.spans.size())
        fuzz::violated("per-span records");
    // Read back from the canonical text: the same spans.
    const std::string canonical = render(job);
    host::JobSpans again;
    try {
        again = host::parse_job_spans(canonical, "j.plan", host::content_hash(canonical));
    } catch (const std::exception& e) {
        fuzz::violated(std::string("canonical form refused: ") + e.what());
    }
    if (render(again) != canonical) fuzz::violated("canonical form does not round-trip");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const std::string text = fuzz::text_of(data + 1, size - 1);
    if ((data[0] & 1u) == 0) {
        journal(text);
    } else {
        spans(text);
    }
    return 0;
}
