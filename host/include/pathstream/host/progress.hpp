// A progress bar with ETA for long work, drawn on a terminal and silent when piped.
#pragma once

#include <chrono>
#include <cstdio>
#include <string>

namespace pathstream::host {

/// Draws "LABEL [######....]  45%  ETA 3 s" on `stream` (default stderr), redrawn at most ten
/// times a second. Enabled only when the stream is a terminal, so logs and pipes stay clean.
/// Not thread-safe: update it from the thread doing the work.
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
    /// Draws 100 % and ends the line (also done by the destructor if still open).
    void finish();
    bool enabled() const { return enabled_; }

    /// The line for `fraction` after `elapsed` seconds, without control characters; exposed
    /// for tests.
    static std::string render(const std::string& label, double fraction, double elapsed_seconds);

private:
    void draw(double fraction);

    std::string label_;
    std::string detail_;
    std::FILE* stream_;
    bool enabled_;
    bool open_ = true;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_draw_{};
};

}  // namespace pathstream::host
