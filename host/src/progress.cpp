#include "pathstream/host/progress.hpp"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace pathstream::host {
namespace {

// The terminal's columns; COLUMNS or 80 when the stream does not say.
std::size_t terminal_width(std::FILE* stream) {
    winsize w{};
    if (::ioctl(fileno(stream), TIOCGWINSZ, &w) == 0 && w.ws_col > 0) return w.ws_col;
    if (const char* columns = std::getenv("COLUMNS")) {
        const long n = std::strtol(columns, nullptr, 10);
        if (n > 0 && n < 10000) return static_cast<std::size_t>(n);
    }
    return 80;
}

}  // namespace

std::string duration_text(double seconds) {
    char text[32];
    if (seconds < 100) {
        std::snprintf(text, sizeof text, "%.0f s", std::ceil(seconds));
    } else if (seconds < 6000) {
        std::snprintf(text, sizeof text, "%.0f min %02.0f s", std::floor(seconds / 60),
                      std::fmod(std::ceil(seconds), 60.0));
    } else {
        std::snprintf(text, sizeof text, "%.1f h", seconds / 3600);
    }
    return text;
}

ProgressBar::ProgressBar(std::string label, std::FILE* stream)
    : ProgressBar(std::move(label), stream, isatty(fileno(stream)) != 0) {}

ProgressBar::ProgressBar(std::string label, std::FILE* stream, bool enabled)
    : label_(std::move(label)),
      stream_(stream),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() {
    if (open_) finish();
}

std::string ProgressBar::render(const std::string& label, double fraction, double elapsed,
                                const std::string& detail, const ProgressEta& eta,
                                std::size_t width) {
    fraction = std::clamp(fraction, 0.0, 1.0);
    const char* mark = eta.estimated ? "~" : "";
    char pct[16];
    std::snprintf(pct, sizeof pct, "%3d%%%s", static_cast<int>(fraction * 100), mark);
    std::string after = pct;
    if (fraction >= 1.0 && !eta.estimated) {
        char done[32];
        std::snprintf(done, sizeof done, "  %.1f s", elapsed);
        after += done;
    } else if (eta.seconds) {
        after += std::string("  ETA ") + mark + duration_text(std::max(0.0, *eta.seconds));
    } else if (fraction > 0.01 && elapsed > 0.2) {
        after += "  ETA " + duration_text(elapsed * (1.0 - fraction) / fraction);
    }
    if (!detail.empty()) after += "  " + detail;
    // label + " [" + bar + "] " + after, kept under `width` so that a terminal never wraps it
    // (one column spare: some terminals wrap when the last one is written).
    constexpr std::size_t kBar = 30, kMinBar = 10;
    std::size_t bar = kBar;
    const std::size_t fixed = label.size() + 4;
    if (width > 0) {
        const std::size_t room = width > 1 ? width - 1 : 1;
        if (fixed + bar + after.size() > room)
            bar = room > fixed + after.size() ? room - fixed - after.size() : 0;
        bar = std::max(bar, kMinBar);
    }
    const std::size_t filled =
        static_cast<std::size_t>(std::lround(fraction * static_cast<double>(bar)));
    std::string line =
        label + " [" + std::string(filled, '#') + std::string(bar - filled, '.') + "] " + after;
    if (width > 0 && line.size() > width - 1) {
        line.resize(width > 4 ? width - 4 : 0);
        line += "...";
    }
    return line;
}

void ProgressBar::draw() {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const std::string line =
        render(label_, fraction_, elapsed, detail_, eta_, terminal_width(stream_));
    std::fprintf(stream_, "\r%s\x1b[K", line.c_str());
    std::fflush(stream_);
    drawn_ = true;
}

void ProgressBar::update(double fraction) {
    update(fraction, detail_, ProgressEta{});
}

void ProgressBar::update(double fraction, const std::string& detail) {
    update(fraction, detail, ProgressEta{});
}

void ProgressBar::update(double fraction, const std::string& detail, const ProgressEta& eta) {
    fraction_ = std::clamp(fraction, 0.0, 1.0);
    detail_ = detail;
    eta_ = eta;
    if (!enabled_ || !open_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    draw();
}

void ProgressBar::finish() {
    if (!open_) return;
    open_ = false;
    if (!enabled_) return;
    draw();
    std::fputc('\n', stream_);
    std::fflush(stream_);
}

}  // namespace pathstream::host
