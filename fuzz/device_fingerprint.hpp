// Shared by the decoder fuzz targets: what a refused write must leave as it was.
#pragma once

#include <array>
#include <cstdint>

#include "pathstream/device/motion_device.hpp"

namespace pathstream::fuzz {

// The producer-side state a write can change, plus the tick's published status.
template <unsigned Axes, std::uint32_t Capacity>
std::array<std::uint64_t, 12 + Axes> fingerprint(const device::MotionDevice<Axes, Capacity>& d) {
    const device::DeviceStatus<Axes> s = d.status();
    std::array<std::uint64_t, 12 + Axes> f = {d.configured(),
                                              d.limits().tick_hz,
                                              d.limits().pen_down_ticks,
                                              d.free_slots(),
                                              d.last_accepted_sequence(),
                                              d.duplicates(),
                                              d.queued_spans(),
                                              s.state,
                                              s.fault_code,
                                              s.epoch,
                                              d.command_pending(),
                                              d.position_pending()};
    for (unsigned a = 0; a < Axes; ++a) f[12 + a] = static_cast<std::uint64_t>(s.position[a]);
    return f;
}

// Limits every fuzz target may configure with: 1 kHz, generous but finite.
template <unsigned Axes>
device::MotionLimits<Axes> fuzz_limits() {
    device::MotionLimits<Axes> l;
    l.tick_hz = 1000;
    for (unsigned a = 0; a < Axes; ++a) {
        l.axis[a].max_velocity = 1000000;
        l.axis[a].max_acceleration = 100000000;
    }
    l.pen_down_ticks = 10;
    return l;
}

// Reads the fuzz input front to back; past its end every read is 0.
class Input {
public:
    Input(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
    bool done() const { return at_ >= size_; }
    std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
    std::uint16_t u16() { return static_cast<std::uint16_t>(byte() << 8 | byte()); }
    std::size_t left() const { return at_ < size_ ? size_ - at_ : 0; }
    const std::uint8_t* here() const { return data_ + at_; }
    void skip(std::size_t n) { at_ += n; }

private:
    const std::uint8_t* data_;
    std::size_t size_;
    std::size_t at_ = 0;
};

}  // namespace pathstream::fuzz
