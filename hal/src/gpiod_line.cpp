// libgpiod 1.6 backend. Active-low is inverted here, not with GPIOD_LINE_REQUEST_FLAG_ACTIVE_LOW:
// the v1 kernel interface labels both-edge events by re-reading the line, so doing the
// inversion in one place keeps levels and edges consistent whatever the kernel does.
#include <gpiod.h>
#include <poll.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "pathstream/hal/gpio_gpiod.hpp"

namespace pathstream::hal {
namespace {

std::string describe(const GpioLineSpec& spec) {
    return "gpio " + spec.chip + " line \"" + spec.line + "\"";
}

[[noreturn]] void fail(const GpioLineSpec& spec, const std::string& what, int error) {
    throw GpioError(describe(spec) + ": " + what +
                    (error != 0 ? std::string(": ") + std::strerror(error) : ""));
}

bool all_digits(const std::string& s) {
    if (s.empty()) return false;
    for (char c : s) {
        if (c < '0' || c > '9') return false;
    }
    return true;
}

// Opens the chip by path, name, number or label (gpiod_chip_open_lookup covers the first three
// and labels too, but says nothing about which one failed: the label search is done here).
gpiod_chip* open_chip(const GpioLineSpec& spec) {
    const std::string& c = spec.chip;
    if (c.empty()) fail(spec, "no chip given", 0);
    gpiod_chip* chip = nullptr;
    if (c[0] == '/') {
        chip = gpiod_chip_open(c.c_str());
    } else if (c.rfind("gpiochip", 0) == 0) {
        chip = gpiod_chip_open_by_name(c.c_str());
    } else if (all_digits(c)) {
        chip = gpiod_chip_open_by_number(static_cast<unsigned>(std::stoul(c)));
    } else {
        errno = ENOENT;
        gpiod_chip_iter* it = gpiod_chip_iter_new();
        if (it == nullptr) fail(spec, "cannot list GPIO chips", errno);
        gpiod_chip* candidate = nullptr;
        gpiod_foreach_chip_noclose(it, candidate) {
            if (chip == nullptr && c == gpiod_chip_label(candidate)) {
                chip = candidate;
            } else {
                gpiod_chip_close(candidate);
            }
        }
        gpiod_chip_iter_free_noclose(it);
        if (chip == nullptr) fail(spec, "no GPIO chip is named or labelled \"" + c + "\"", 0);
    }
    if (chip == nullptr) fail(spec, "cannot open the GPIO chip", errno);
    return chip;
}

gpiod_line* find_line(gpiod_chip* chip, const GpioLineSpec& spec) {
    if (spec.line.empty()) fail(spec, "no line given", 0);
    if (all_digits(spec.line)) {
        const unsigned long offset = std::stoul(spec.line);
        if (offset >= gpiod_chip_num_lines(chip)) {
            fail(spec,
                 "offset out of range (the chip has " + std::to_string(gpiod_chip_num_lines(chip)) +
                     " lines)",
                 0);
        }
        gpiod_line* line = gpiod_chip_get_line(chip, static_cast<unsigned>(offset));
        if (line == nullptr) fail(spec, "cannot get the line", errno);
        return line;
    }
    gpiod_line* line = gpiod_chip_find_line(chip, spec.line.c_str());
    if (line == nullptr) fail(spec, "the chip has no line of that name", 0);
    return line;
}

int bias_flags(Bias bias) {
    switch (bias) {
        case Bias::kDisable:
            return GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE;
        case Bias::kPullUp:
            return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP;
        case Bias::kPullDown:
            return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN;
        case Bias::kAsIs:
        default:
            return 0;
    }
}

// Owns the chip handle; the line is released with the chip.
class Line {
public:
    explicit Line(const GpioLineSpec& spec) : spec_(spec), chip_(open_chip(spec)) {
        try {
            line_ = find_line(chip_, spec);
        } catch (...) {
            gpiod_chip_close(chip_);
            throw;
        }
    }
    ~Line() { gpiod_chip_close(chip_); }  // releases the line too
    Line(const Line&) = delete;
    Line& operator=(const Line&) = delete;

    void request(int type, const std::string& consumer, int default_value) {
        gpiod_line_request_config cfg{consumer.c_str(), type, bias_flags(spec_.bias)};
        if (gpiod_line_request(line_, &cfg, default_value) != 0) {
            const int e = errno;
            const char* holder = gpiod_line_consumer(line_);
            std::string what = type == GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES ? "request edge events"
                                                                           : "request as output";
            if (e == EBUSY && holder != nullptr)
                what += " (in use by \"" + std::string(holder) + "\")";
            fail(spec_, what, e);
        }
    }

    const GpioLineSpec spec_;
    gpiod_chip* chip_;
    gpiod_line* line_ = nullptr;
};

class GpiodInput final : public DigitalInput {
public:
    GpiodInput(const GpioLineSpec& spec, const std::string& consumer) : line_(spec) {
        line_.request(GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES, consumer, 0);
        fd_ = gpiod_line_event_get_fd(line_.line_);
        if (fd_ < 0) fail(spec, "no event file descriptor", errno);
    }

    bool active() override {
        const int v = gpiod_line_get_value(line_.line_);
        if (v < 0) fail(line_.spec_, "read the level", errno);
        return (v != 0) != line_.spec_.active_low;
    }

    bool next_edge(InputEdge& edge) override {
        pollfd p{fd_, POLLIN, 0};
        const int r = ::poll(&p, 1, 0);
        if (r < 0) fail(line_.spec_, "poll the event file descriptor", errno);
        if (r == 0) return false;
        gpiod_line_event ev{};
        if (gpiod_line_event_read_fd(fd_, &ev) != 0) fail(line_.spec_, "read an edge event", errno);
        const bool high = ev.event_type == GPIOD_LINE_EVENT_RISING_EDGE;
        edge.active = high != line_.spec_.active_low;
        edge.timestamp_ns = static_cast<std::uint64_t>(ev.ts.tv_sec) * 1000000000u +
                            static_cast<std::uint64_t>(ev.ts.tv_nsec);
        return true;
    }

    int event_fd() const override { return fd_; }

private:
    Line line_;
    int fd_ = -1;
};

class GpiodOutput final : public DigitalOutput {
public:
    GpiodOutput(const GpioLineSpec& spec, const std::string& consumer, bool initially_active)
        : line_(spec) {
        line_.request(GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, consumer, level(initially_active));
        state_ = initially_active;
    }

    void set(bool active) override {
        if (active == state_) return;  // one ioctl per change, none per tick
        if (gpiod_line_set_value(line_.line_, level(active)) != 0)
            fail(line_.spec_, "drive the output", errno);
        state_ = active;
    }

private:
    int level(bool active) const { return active != line_.spec_.active_low ? 1 : 0; }

    Line line_;
    bool state_ = false;
};

}  // namespace

std::unique_ptr<DigitalInput> open_gpiod_input(const GpioLineSpec& spec,
                                               const std::string& consumer) {
    return std::make_unique<GpiodInput>(spec, consumer);
}

std::unique_ptr<DigitalOutput> open_gpiod_output(const GpioLineSpec& spec,
                                                 const std::string& consumer,
                                                 bool initially_active) {
    return std::make_unique<GpiodOutput>(spec, consumer, initially_active);
}

GpioLineLocation locate_gpiod_line(const GpioLineSpec& spec) {
    gpiod_chip* chip = open_chip(spec);
    GpioLineLocation where;
    try {
        gpiod_line* line = find_line(chip, spec);
        where.chip_name = gpiod_chip_name(chip);
        where.offset = gpiod_line_offset(line);
    } catch (...) {
        gpiod_chip_close(chip);
        throw;
    }
    gpiod_chip_close(chip);
    return where;
}

}  // namespace pathstream::hal
