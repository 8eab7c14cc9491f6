// Job journal: the job's spans file and the progress record, each written atomically; the move
// back onto the drawing that a resume streams is resume_path.cpp's.
#include "pathstream/host/job_journal.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "pathstream/machine/atomic_file.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/json_document.hpp"

namespace pathstream::host {
namespace {

constexpr const char* kSpansHeader = "pathstream job spans 1";

// FNV-1a 64 over bytes given in pieces.
struct Fnv1a {
    std::uint64_t h = 1469598103934665603ull;
    void add(const char* data, std::size_t size) {
        for (std::size_t i = 0; i < size; ++i) {
            h ^= static_cast<unsigned char>(data[i]);
            h *= 1099511628211ull;
        }
    }
    std::string hex() const {
        char out[17];
        std::snprintf(out, sizeof out, "%016llx", static_cast<unsigned long long>(h));
        return out;
    }
};

std::string fnv1a_hex(const std::string& text) {
    Fnv1a f;
    f.add(text.data(), text.size());
    return f.hex();
}

// Subpaths of the drawing: its spans name them by index.
std::size_t count_subpaths(const Plan& plan) {
    std::size_t n = 0;
    for (const CoreSpan& s : plan.spans) n = std::max(n, s.subpath + 1);
    return n;
}

}  // namespace

std::vector<PlanPause> pauses_from_spans(const std::vector<CoreSpan>& spans) {
    std::vector<PlanPause> out;
    std::uint64_t tick = 0;
    for (std::size_t i = 0; i < spans.size(); ++i) {
        tick += spans[i].ticks;
        if (spans[i].pause_after)
            out.push_back({tick, i + 1 < spans.size() ? spans[i + 1].subpath : spans[i].subpath});
    }
    return out;
}

JobSpans job_from_plan(const Plan& plan) {
    JobSpans j;
    j.plan = plan;
    std::uint64_t tick = 0;
    for (std::size_t i = 0; i < plan.spans.size(); ++i) {
        j.origin.push_back(static_cast<std::int64_t>(i));
        j.drawing_tick.push_back(tick);
        tick += plan.spans[i].ticks;
    }
    j.drawing_spans = plan.spans.size();
    j.drawing_ticks = tick;
    j.subpaths = count_subpaths(plan);
    return j;
}

JobSpansWriter::JobSpansWriter(std::string path, bool partial)
    : path_(std::move(path)),
      body_(partial ? std::fopen(partial_spans_path(path_).c_str(), "w+") : std::tmpfile()),
      partial_(partial) {
    if (body_ == nullptr) {
        throw std::runtime_error(
            (partial ? partial_spans_path(path_) : path_) +
            ": cannot make a file for the job's spans: " + std::strerror(errno));
    }
}

JobSpansWriter::~JobSpansWriter() {
    if (body_ != nullptr) std::fclose(body_);
}

std::string job_span_line(const CoreSpan& s, std::int64_t origin, std::uint64_t drawing_tick) {
    char buffer[96];
    std::string line;
    std::snprintf(buffer, sizeof buffer, "%lld %llu %zu %d %u", static_cast<long long>(origin),
                  static_cast<unsigned long long>(drawing_tick), s.subpath,
                  (s.pen_down ? 1 : 0) | (s.pause_after ? 2 : 0) | (s.machine << 1),
                  static_cast<unsigned>(s.ticks));
    line = buffer;
    for (const auto& c : s.control) {
        std::snprintf(buffer, sizeof buffer, " %d %d %d %d", c[0], c[1], c[2], c[3]);
        line += buffer;
    }
    return line;
}

std::string content_hash(const std::string& bytes) {
    return fnv1a_hex(bytes);
}

void JobSpansWriter::add(const CoreSpan& s, std::int64_t origin, std::uint64_t drawing_tick) {
    if (spans_ == 0) axes_ = s.control.size();
    std::string line = job_span_line(s, origin, drawing_tick);
    line += '\n';
    if (std::fwrite(line.data(), 1, line.size(), body_) != line.size() ||
        (partial_ && std::fflush(body_) != 0)) {
        throw std::runtime_error((partial_ ? partial_spans_path(path_) : path_) +
                                 ": cannot write the job's spans: " + std::strerror(errno));
    }
    ++spans_;
}

std::string JobSpansWriter::finish(std::size_t drawing_spans, std::uint64_t drawing_ticks,
                                   std::size_t subpaths) {
    std::ostringstream header;
    header << kSpansHeader << '\n';
    header << "axes " << axes_ << " spans " << spans_ << " drawing_spans " << drawing_spans
           << " drawing_ticks " << drawing_ticks << " subpaths " << subpaths << '\n';
    const std::string head = header.str();
    Fnv1a hash;
    hash.add(head.data(), head.size());
    AtomicFile f(path_);
    f.stream() << head;
    if (std::fflush(body_) != 0 || std::fseek(body_, 0, SEEK_SET) != 0) {
        throw std::runtime_error(path_ + ": the job's spans could not be written back");
    }
    char buffer[1 << 16];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, body_)) > 0) {
        hash.add(buffer, n);
        f.stream().write(buffer, static_cast<std::streamsize>(n));
    }
    if (std::ferror(body_))
        throw std::runtime_error(path_ + ": the job's spans could not be read back");
    f.commit();
    if (partial_) std::remove(partial_spans_path(path_).c_str());
    return hash.hex();
}

std::string write_job_spans(const JobSpans& job, const std::string& path) {
    JobSpansWriter w(path);
    for (std::size_t i = 0; i < job.plan.spans.size(); ++i)
        w.add(job.plan.spans[i], job.origin[i], job.drawing_tick[i]);
    return w.finish(job.drawing_spans, job.drawing_ticks, job.subpaths);
}

JobSpans read_job_spans(const std::string& path, const std::string& expected_hash) {
    // A journal edited to name a device or a FIFO (/dev/zero) would be read without end.
    std::error_code ec;
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec)) {
        throw InputError(path, {},
                         "not a regular file: a job's spans are a file that stream writes");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, {}, "cannot open the job's spans");
    std::ostringstream whole;
    whole << in.rdbuf();
    return parse_job_spans(whole.str(), path, expected_hash);
}

JobSpans parse_job_spans(const std::string& contents, const std::string& path,
                         const std::string& expected_hash) {
    if (!expected_hash.empty() && fnv1a_hex(contents) != expected_hash) {
        throw InputError(path, {},
                         "the job's spans changed since the journal was written (hash " +
                             fnv1a_hex(contents) + ", journal " + expected_hash + ")");
    }
    std::istringstream lines(contents);
    std::string line;
    std::size_t number = 0;
    const auto fail = [&](const std::string& what) -> void {
        throw InputError(path, {number, 1}, what);
    };
    if (!std::getline(lines, line) || line != kSpansHeader) {
        number = 1;
        fail(std::string("not a job spans file (want \"") + kSpansHeader + "\")");
    }
    ++number;
    JobSpans job;
    std::size_t axes = 0, spans = 0;
    {
        std::getline(lines, line);
        ++number;
        std::istringstream h(line);
        std::string k1, k2, k3, k4, k5;
        if (!(h >> k1 >> axes >> k2 >> spans >> k3 >> job.drawing_spans >> k4 >>
              job.drawing_ticks >> k5 >> job.subpaths) ||
            k1 != "axes" || k2 != "spans" || axes < 1 || axes > 8) {
            fail("bad header line");
        }
    }
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < spans; ++i) {
        if (!std::getline(lines, line))
            fail("ends after " + std::to_string(i) + " of " + std::to_string(spans) + " spans");
        ++number;
        std::istringstream l(line);
        CoreSpan s;
        std::int64_t origin = 0;
        std::uint64_t tick = 0;
        // Bit 0: pen down, bit 1: a pause follows, bits 2-5: the machine functions (outputs
        // bits 1-4).
        int marks = 0;
        s.basis = Basis::kHermite;
        if (!(l >> origin >> tick >> s.subpath >> marks >> s.ticks) || s.ticks < 1 || marks < 0 ||
            marks > 3 + (kOutputMachineMask << 1)) {
            fail("bad span line");
        }
        s.pen_down = (marks & 1) != 0;
        s.pause_after = (marks & 2) != 0;
        s.machine = static_cast<std::uint8_t>((marks >> 1) & kOutputMachineMask);
        s.control.assign(axes, {});
        for (auto& c : s.control) {
            if (!(l >> c[0] >> c[1] >> c[2] >> c[3]))
                fail("bad span line: " + std::to_string(axes) + " axes expected");
        }
        total += s.ticks;
        job.plan.spans.push_back(std::move(s));
        job.origin.push_back(origin);
        job.drawing_tick.push_back(tick);
    }
    job.plan.total_ticks = total;
    job.plan.pauses = pauses_from_spans(job.plan.spans);
    return job;
}

std::string journal_binding(const JobJournal& j) {
    // The fields that say which job this is and what it draws; the progress fields and the
    // target (resume may name the device anew) change legitimately and are left out.
    return content_hash("pathstream job binding 1\n" + j.machine + '\n' + j.drawing + '\n' +
                        j.plan_file + '\n' + j.plan_hash + '\n' + std::to_string(j.job) + '\n' +
                        std::to_string(j.epoch) + '\n' + j.replan);
}

void write_journal(const JobJournal& j, const std::string& path) {
    nlohmann::json d;
    d["format"] = "pathstream job journal 1";
    d["target"] = j.target;
    d["machine"] = j.machine;
    d["drawing"] = j.drawing;
    d["plan_file"] = j.plan_file;
    d["plan_hash"] = j.plan_hash;
    d["job"] = j.job;
    d["acknowledged"] = j.acknowledged;
    d["last_completed"] = j.last_completed;
    d["epoch"] = j.epoch;
    d["state"] = j.state;
    d["position_lsb"] = j.position;
    d["outcome"] = j.outcome;
    if (!j.error.empty()) d["error"] = j.error;
    if (!j.pauses.empty()) d["pauses"] = j.pauses;
    if (!j.replan.empty()) d["replan"] = nlohmann::json::parse(j.replan);
    d["binding"] = journal_binding(j);
    AtomicFile f(path);
    f.stream() << d.dump(2) << '\n';
    f.commit();
}

JobJournal read_journal(const std::string& path) {
    std::error_code ec;
    if (std::filesystem::exists(path, ec) && !std::filesystem::is_regular_file(path, ec)) {
        throw InputError(path, {}, "not a regular file: a journal is a file that stream writes");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, {}, "cannot open the journal");
    std::ostringstream whole;
    whole << in.rdbuf();
    return parse_journal(whole.str(), path);
}

JobJournal parse_journal(const std::string& text, const std::string& path) {
    const nlohmann::json d = parse_json_document(text, path);
    const JsonChecker check(text, path);
    // value("format", "") throws a type error for a "format" that is not a string: compared
    // as JSON instead, any other value is simply not this format.
    if (!d.is_object() || !d.contains("format") ||
        d["format"] != nlohmann::json("pathstream job journal 1")) {
        check.fail("",
                   "not a pathstream job journal (want \"format\": \"pathstream job journal 1\")");
    }
    JobJournal j;
    const auto get = [&](const char* key, auto& out) {
        if (!d.contains(key)) check.fail("", std::string("missing \"") + key + "\"");
        try {
            d.at(key).get_to(out);
        } catch (const nlohmann::json::exception&) {
            check.fail(std::string("/") + key, std::string("\"") + key + "\" has the wrong type");
        }
    };
    get("target", j.target);
    get("machine", j.machine);
    get("drawing", j.drawing);
    get("plan_file", j.plan_file);
    get("plan_hash", j.plan_hash);
    get("job", j.job);
    get("acknowledged", j.acknowledged);
    get("last_completed", j.last_completed);
    get("epoch", j.epoch);
    get("state", j.state);
    get("position_lsb", j.position);
    get("outcome", j.outcome);
    if (d.contains("error")) get("error", j.error);
    if (d.contains("pauses")) get("pauses", j.pauses);
    if (d.contains("replan")) {
        if (!d["replan"].is_object()) check.fail("/replan", "\"replan\" must be an object");
        j.replan = d["replan"].dump();
    }
    std::string binding;
    get("binding", binding);
    if (binding != journal_binding(j)) {
        check.fail("/binding",
                   "the journal's job, plan or drawing is not the one it was written with "
                   "(\"binding\" does not match): "
                   "an edited or swapped journal is never resumed");
    }
    return j;
}

}  // namespace pathstream::host
