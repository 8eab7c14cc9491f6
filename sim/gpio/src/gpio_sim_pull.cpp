#include "pathstream/sim/gpio_sim_pull.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "pathstream/hal/gpio_gpiod.hpp"

namespace pathstream::sim {

namespace {

// One whole write of `value` to a sysfs attribute; the kernel applies it at close at latest.
void write_attribute(const std::string& path, const char* value) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) {
        const int e = errno;
        throw hal::GpioError("gpio-sim: cannot open " + path + ": " + std::strerror(e) +
                             (e == ENOENT ? " (is the chip a gpio-sim chip?)" : ""));
    }
    const std::size_t n = std::strlen(value);
    const ssize_t written = ::write(fd, value, n);
    const int e = errno;
    ::close(fd);
    if (written != static_cast<ssize_t>(n)) {
        throw hal::GpioError("gpio-sim: cannot write '" + std::string(value) + "' to " + path +
                             ": " + (written < 0 ? std::strerror(e) : "short write"));
    }
}

}  // namespace

GpioSimPull::GpioSimPull(const std::string& chip_name, unsigned offset, bool active_low,
                         const std::string& sysfs_devices)
    : path_(sysfs_devices + "/" + chip_name + "/sim_gpio" + std::to_string(offset) + "/pull"),
      active_low_(active_low) {
    if (::access(path_.c_str(), W_OK) != 0) {
        const int e = errno;
        throw hal::GpioError("gpio-sim: " + chip_name + " line " + std::to_string(offset) +
                             " cannot be driven from outside: " + path_ + ": " + std::strerror(e) +
                             (e == ENOENT ? " (not a gpio-sim chip)" : ""));
    }
}

void GpioSimPull::set(bool active) {
    write_attribute(path_, active != active_low_ ? "pull-up" : "pull-down");
}

}  // namespace pathstream::sim
