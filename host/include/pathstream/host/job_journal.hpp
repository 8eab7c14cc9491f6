// A stream's record on disk, so that an interrupted drawing can be continued after a hold, a
// stop, a fault reset, a device restart or a host crash (docs/cli.md, "Interrupt and
// resume"). Two files: the job's spans (JOURNAL.plan, written once per job) and the journal
// itself (JSON, rewritten as the stream goes). Both are written atomically. The move back onto
// the drawing that a resume streams is resume_path.hpp's.
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "pathstream/host/plan.hpp"
#include "pathstream/units.hpp"

namespace pathstream::host {

/// The spans of one job as streamed, each with where it sits in the drawing.
struct JobSpans {
    Plan plan;  ///< Hermite spans, as encode_wire_plan takes them
    std::vector<std::int64_t>
        origin;  ///< per span: index in the drawing's plan, -1 for a re-entry span
    std::vector<std::uint64_t> drawing_tick;  ///< per span: the drawing's tick at its start
                                              ///< (re-entry: of the span it leads to)
    std::size_t drawing_spans = 0;            ///< spans of the whole drawing
    std::uint64_t drawing_ticks = 0;          ///< ticks of the whole drawing
    std::size_t subpaths = 0;                 ///< pen-down subpaths of the whole drawing
};

/// A drawing's plan as the first job: every span its own origin.
JobSpans job_from_plan(const Plan& plan);

/// The programmed pauses of a plan made of `spans` (Plan::pauses), from their pause_after
/// marks: what a spans file, which keeps only the marks, and a resumed job's spans imply.
std::vector<PlanPause> pauses_from_spans(const std::vector<CoreSpan>& spans);

/// Writes a job's spans file as the spans come, holding none of them: the span lines go to a
/// temporary file, and finish() writes `path` atomically (the header, which needs the totals,
/// first). Nothing appears at `path` before finish(). One thread.
class JobSpansWriter {
public:
    /// `partial` false: the lines go to an anonymous temporary file. `partial` true: they go to
    /// partial_spans_path(path), each flushed to the kernel by add() before it returns, so a
    /// span handed on after add() is in that file even if the process is killed the next
    /// instant (a host crash while planning: --resume proves its new plan against it);
    /// finish() removes it. Throws std::runtime_error when the file cannot be made.
    explicit JobSpansWriter(std::string path, bool partial = false);
    ~JobSpansWriter();
    JobSpansWriter(const JobSpansWriter&) = delete;
    JobSpansWriter& operator=(const JobSpansWriter&) = delete;
    /// The job's next span: its index in the drawing's plan (-1: a re-entry span) and the
    /// drawing's tick at its start. O(axes).
    void add(const CoreSpan& span, std::int64_t origin, std::uint64_t drawing_tick);
    /// Writes the file (the whole drawing's spans, ticks and subpaths in the header); returns
    /// its FNV-1a 64 hash, hex. Throws std::runtime_error when the file cannot be written.
    std::string finish(std::size_t drawing_spans, std::uint64_t drawing_ticks,
                       std::size_t subpaths);

private:
    std::string path_;
    std::FILE* body_ = nullptr;
    bool partial_ = false;
    std::size_t spans_ = 0;
    std::size_t axes_ = 0;
};

/// Where a partial JobSpansWriter keeps the lines of a spans file not yet finished.
inline std::string partial_spans_path(const std::string& path) {
    return path + ".partial";
}

/// One span's line in a spans file (no newline): what JobSpansWriter::add writes.
std::string job_span_line(const CoreSpan& span, std::int64_t origin, std::uint64_t drawing_tick);

/// The FNV-1a 64 hash of `bytes`, hex (16 digits): the hash the journal keeps of its files.
std::string content_hash(const std::string& bytes);

/// Writes `job` to `path` atomically (one line per span, with JobSpansWriter); returns its
/// FNV-1a 64 hash, hex.
std::string write_job_spans(const JobSpans& job, const std::string& path);
/// Reads what write_job_spans wrote. Throws InputError (`path:line:col: what`) for anything
/// else, and when the contents do not hash to `expected_hash` (unless it is empty).
JobSpans read_job_spans(const std::string& path, const std::string& expected_hash);
/// read_job_spans on `contents` already read, `path` naming them in errors. Cost: O(bytes);
/// memory O(spans), never more than the text holds.
JobSpans parse_job_spans(const std::string& contents, const std::string& path,
                         const std::string& expected_hash);

/// The journal: what was streamed where, and how far the device got.
struct JobJournal {
    std::string target;     ///< the device's URL
    std::string machine;    ///< the machine profile's path
    std::string drawing;    ///< the drawing's path (for messages)
    std::string plan_file;  ///< the job's spans (write_job_spans)
    std::string plan_hash;
    std::uint32_t job = 0;  ///< the device's id of the job (its first span's sequence number); 0
                            ///< before the first batch
    std::uint32_t acknowledged = 0;    ///< last sequence number the device acknowledged
    std::uint32_t last_completed = 0;  ///< last sequence number executed to its end
    std::uint32_t epoch = 0;           ///< the device's queue epoch at the last read
    std::string state = "starting";    ///< the device's state at the last read
    std::vector<Lsb> position;         ///< where the device was at the last read
    /// "streaming", "held" (interrupted, the rest queued), "stopped" (interrupted, queue
    /// dropped), "failed" (the stream ended with an error: `error`), "finished".
    std::string outcome = "streaming";
    std::string error;
    /// Per programmed pause of the drawing (Plan::pauses, in order): what comes after it, for
    /// the operator (`layer "blue"`). Optional in the file.
    std::vector<std::string> pauses;
    /// How to plan the job again when its plan was not complete (a stream that plans as it
    /// goes): a JSON object whose keys the stream command defines (the drawing's copy, the
    /// path options, hashes). Empty: none. Optional in the file ("replan").
    std::string replan;

    /// True while the device has accepted none of the job's spans (no batch yet, or the
    /// acknowledged number still the one before the job's first): nothing of it can have moved.
    bool nothing_accepted() const { return job == 0 || acknowledged + 1 == job; }
};

/// The hash that binds a journal to its job: content_hash over the machine, drawing, plan file,
/// plan hash, job id, epoch and replan (not the progress fields, not the target). Written as
/// "binding"; a journal whose binding does not match its fields is refused.
std::string journal_binding(const JobJournal& journal);
/// Writes `journal` to `path` atomically (JSON), with its binding.
void write_journal(const JobJournal& journal, const std::string& path);
/// Reads a journal. Throws InputError naming the file, line and column, or the missing key,
/// or "binding" when the journal's identity fields were changed after it was written.
JobJournal read_journal(const std::string& path);
/// read_journal on `text` already read, `path` naming it in errors.
JobJournal parse_journal(const std::string& text, const std::string& path);

}  // namespace pathstream::host
