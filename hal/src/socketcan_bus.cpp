#include "pathstream/hal/socketcan_bus.hpp"

#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <system_error>

namespace pathstream::hal {
namespace {

[[noreturn]] void fail(const std::string& name, const char* what, int error) {
    throw std::system_error(error, std::generic_category(), "CAN interface " + name + ": " + what);
}

}  // namespace

SocketCanBus::SocketCanBus(const std::string& name, const std::vector<CanFilter>& filters)
    : name_(name) {
    if (name.empty() || name.size() >= IFNAMSIZ) fail(name, "bad interface name", EINVAL);
    const unsigned index = if_nametoindex(name.c_str());
    if (index == 0)
        fail(name, "no such interface (for a virtual one: ip link add dev NAME type vcan)", errno);
    fd_ = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd_ < 0) fail(name, "cannot open a raw CAN socket (is the can-raw module loaded?)", errno);
    try {
        const can_err_mask_t errors = CAN_ERR_MASK;
        if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errors, sizeof errors) != 0) {
            fail(name, "cannot enable error frames", errno);
        }
        if (!filters.empty()) set_filters(filters);
        sockaddr_can addr{};
        addr.can_family = AF_CAN;
        addr.can_ifindex = static_cast<int>(index);
        if (::bind(fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0) {
            fail(name, "cannot bind (not a CAN interface, or down?)", errno);
        }
    } catch (...) {
        ::close(fd_);
        throw;
    }
}

SocketCanBus::~SocketCanBus() {
    if (fd_ >= 0) ::close(fd_);
}

void SocketCanBus::set_filters(const std::vector<CanFilter>& filters) {
    std::vector<can_filter> f;
    for (const CanFilter& c : filters) {
        can_filter k{};
        k.can_id = c.extended ? (c.id & CAN_EFF_MASK) | CAN_EFF_FLAG : c.id & CAN_SFF_MASK;
        // The EFF flag is part of the match, so a standard filter never passes extended frames.
        k.can_mask = (c.extended ? c.mask & CAN_EFF_MASK : c.mask & CAN_SFF_MASK) | CAN_EFF_FLAG |
                     CAN_RTR_FLAG;
        f.push_back(k);
    }
    const void* data = f.empty() ? nullptr : f.data();
    const auto size = static_cast<socklen_t>(f.size() * sizeof(can_filter));
    if (f.empty()) {
        // Everything: one filter with a zero mask.
        can_filter all{};
        if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, &all, sizeof all) != 0) {
            fail(name_, "cannot set receive filters", errno);
        }
        return;
    }
    if (::setsockopt(fd_, SOL_CAN_RAW, CAN_RAW_FILTER, data, size) != 0)
        fail(name_, "cannot set receive filters", errno);
}

CanSendResult SocketCanBus::send(const CanFrame& frame) {
    if (state_ == CanBusState::kBusOff) return CanSendResult::kBusOff;
    if (frame.length > 8 || (!frame.extended && frame.id > CAN_SFF_MASK) ||
        frame.id > CAN_EFF_MASK) {
        return CanSendResult::kError;
    }
    can_frame f{};
    f.can_id = frame.id | (frame.extended ? CAN_EFF_FLAG : 0u) | (frame.remote ? CAN_RTR_FLAG : 0u);
    f.len = frame.length;
    std::memcpy(f.data, frame.data, frame.length);
    const ssize_t n = ::write(fd_, &f, sizeof f);
    if (n == static_cast<ssize_t>(sizeof f)) {
        ++counters_.frames_sent;
        return CanSendResult::kQueued;
    }
    if (n < 0 && (errno == ENOBUFS || errno == EAGAIN)) {
        ++counters_.tx_queue_full;
        return CanSendResult::kQueueFull;
    }
    return CanSendResult::kError;
}

bool SocketCanBus::receive(CanFrame& out, std::uint32_t timeout_us) {
    using clock = std::chrono::steady_clock;
    const auto deadline = clock::now() + std::chrono::microseconds(timeout_us);
    while (true) {
        can_frame f{};
        const ssize_t n = ::read(fd_, &f, sizeof f);
        if (n == static_cast<ssize_t>(sizeof f)) {
            if ((f.can_id & CAN_ERR_FLAG) != 0) {
                std::uint8_t data[8];
                std::memcpy(data, f.data, 8);
                on_error_frame(f.can_id & CAN_ERR_MASK, data);
                continue;
            }
            out = CanFrame{};
            out.extended = (f.can_id & CAN_EFF_FLAG) != 0;
            out.remote = (f.can_id & CAN_RTR_FLAG) != 0;
            out.id = f.can_id & (out.extended ? CAN_EFF_MASK : CAN_SFF_MASK);
            out.length = f.len > 8 ? 8 : f.len;
            std::memcpy(out.data, f.data, out.length);
            ++counters_.frames_received;
            return true;
        }
        if (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) return false;
        const auto left =
            std::chrono::duration_cast<std::chrono::microseconds>(deadline - clock::now()).count();
        if (left <= 0) return false;
        pollfd p{fd_, POLLIN, 0};
        const int ms = static_cast<int>((left + 999) / 1000);
        if (::poll(&p, 1, ms) <= 0 && clock::now() >= deadline) return false;
    }
}

void SocketCanBus::on_error_frame(std::uint32_t can_id, const std::uint8_t (&data)[8]) {
    ++counters_.error_frames;
    if ((can_id & CAN_ERR_BUSOFF) != 0) {
        if (state_ != CanBusState::kBusOff) ++counters_.bus_off_events;
        state_ = CanBusState::kBusOff;
        return;
    }
    if ((can_id & CAN_ERR_RESTARTED) != 0) {
        ++counters_.restarts;
        state_ = CanBusState::kErrorActive;
        return;
    }
    if ((can_id & CAN_ERR_CRTL) != 0) {
        const std::uint8_t c = data[1];
        if ((c & (CAN_ERR_CRTL_RX_PASSIVE | CAN_ERR_CRTL_TX_PASSIVE)) != 0) {
            state_ = CanBusState::kErrorPassive;
        } else if ((c & (CAN_ERR_CRTL_RX_WARNING | CAN_ERR_CRTL_TX_WARNING)) != 0) {
            if (state_ != CanBusState::kErrorPassive) state_ = CanBusState::kErrorWarning;
        }
#ifdef CAN_ERR_CRTL_ACTIVE
        if ((c & CAN_ERR_CRTL_ACTIVE) != 0) state_ = CanBusState::kErrorActive;
#endif
    }
}

}  // namespace pathstream::hal
