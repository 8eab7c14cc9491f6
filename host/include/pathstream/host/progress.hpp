// A progress bar with ETA for long work, drawn on a terminal and silent when piped.
#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <optional>
#include <string>

namespace pathstream::host {

/// A duration as a person reads it: "42 s", "12 min 05 s", "6.7 h".
std::string duration_text(double seconds);

/// What a line says after the percentage: the time left, when the caller knows it better than
/// an extrapolation of the wall time (motion left at the tick rate, after a resume too), and
/// whether it and the fraction are an estimate (the job's length not planned yet).
struct ProgressEta {
    std::optional<double> seconds;  ///< nullopt: extrapolated from the elapsed wall time
    bool estimated = false;         ///< drawn as "~": the fraction and ETA are estimates
};

/// Draws "LABEL [######....]  45%  ETA 3 s  DETAIL" on `stream` (default stderr) as one line
/// redrawn in place at most ten times a second, cut to the terminal's width (the bar narrows
/// first, then the detail is shortened) so that it never wraps. Enabled only when the stream
/// is a terminal, so logs and pipes stay clean. Not thread-safe: update it from the thread
/// doing the work.
class ProgressBar {
public:
    explicit ProgressBar(std::string label, std::FILE* stream = stderr);
    ProgressBar(std::string label, std::FILE* stream, bool enabled);
    ~ProgressBar();
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    /// Reports progress in [0, 1]; values outside are clamped.
    void update(double fraction);
    /// The same, with a short text shown after the ETA (e.g. a queue level).
    void update(double fraction, const std::string& detail);
    /// The same, with the time left given (see ProgressEta).
    void update(double fraction, const std::string& detail, const ProgressEta& eta);
    /// Draws the last fraction reported (100 % only if the work got there: an interrupted job
    /// ends the line where it stopped) and ends the line; also done by the destructor.
    void finish();
    bool enabled() const { return enabled_; }

    /// The line for `fraction` after `elapsed` seconds, at most `width` characters (0: no
    /// limit), without control characters; exposed for tests.
    static std::string render(const std::string& label, double fraction, double elapsed_seconds,
                              const std::string& detail = "", const ProgressEta& eta = {},
                              std::size_t width = 0);

private:
    void draw();

    std::string label_;
    std::string detail_;
    ProgressEta eta_;
    double fraction_ = 0;
    std::FILE* stream_;
    bool enabled_;
    bool open_ = true;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_draw_{};
};

}  // namespace pathstream::host
