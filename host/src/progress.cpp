#include "pathstream/host/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>

namespace pathstream::host {

ProgressBar::ProgressBar(std::string label, std::FILE* stream)
    : ProgressBar(std::move(label), stream, isatty(fileno(stream)) != 0) {}

ProgressBar::ProgressBar(std::string label, std::FILE* stream, bool enabled)
    : label_(std::move(label)), stream_(stream), enabled_(enabled), start_(std::chrono::steady_clock::now()) {}

ProgressBar::~ProgressBar() {
    if (open_) finish();
}

std::string ProgressBar::render(const std::string& label, double fraction, double elapsed) {
    constexpr int kWidth = 30;
    fraction = std::clamp(fraction, 0.0, 1.0);
    const int filled = static_cast<int>(std::lround(fraction * kWidth));
    std::string line = label + " [" + std::string(static_cast<std::size_t>(filled), '#') +
                       std::string(static_cast<std::size_t>(kWidth - filled), '.') + "] ";
    char pct[16];
    std::snprintf(pct, sizeof pct, "%3d%%", static_cast<int>(fraction * 100));
    line += pct;
    if (fraction >= 1.0) {
        char done[32];
        std::snprintf(done, sizeof done, "  %.1f s", elapsed);
        return line + done;
    }
    if (fraction > 0.01 && elapsed > 0.2) {
        const double eta = elapsed * (1.0 - fraction) / fraction;
        char text[32];
        std::snprintf(text, sizeof text, "  ETA %.0f s", std::ceil(eta));
        line += text;
    }
    return line;
}

void ProgressBar::draw(double fraction) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    std::string line = render(label_, fraction, elapsed);
    if (!detail_.empty()) line += "  " + detail_;
    std::fprintf(stream_, "\r%s\x1b[K", line.c_str());
    std::fflush(stream_);
}

void ProgressBar::update(double fraction) {
    if (!enabled_ || !open_) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    draw(fraction);
}

void ProgressBar::update(double fraction, const std::string& detail) {
    detail_ = detail;
    update(fraction);
}

void ProgressBar::finish() {
    if (!open_) return;
    open_ = false;
    if (!enabled_) return;
    draw(1.0);
    std::fputc('\n', stream_);
    std::fflush(stream_);
}

}  // namespace pathstream::host
