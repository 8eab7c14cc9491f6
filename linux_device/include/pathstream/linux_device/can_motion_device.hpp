// The native CAN device: the firmware core's MotionDevice behind the native CAN
// protocol (device::can::CanNode) on any hal::CanBus, ticked on the steady clock. What
// `pathstream device --can IFACE --node N` runs and what the CAN streaming tests talk to.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <vector>

#include "pathstream/hal/can_bus.hpp"
#include "pathstream/linux_device/any_motion_device.hpp"
#include "pathstream/linux_device/paced_loop.hpp"
#include "pathstream/units.hpp"

namespace pathstream::linux_device {

/// Span queue depth of the CAN device.
inline constexpr std::uint32_t kCanDeviceCapacity = 64;

/// A MotionDevice<axes, kCanDeviceCapacity> with its CAN node, type-erased over the axis
/// count. Not thread-safe: one thread serves and ticks it.
class CanMotionDevice : public AnyMotionDevice {
public:
    /// `start`: initial position (LSB), its size is the axis count (1..8); `node` 1..127.
    /// Throws std::invalid_argument otherwise.
    static std::unique_ptr<CanMotionDevice> create(const std::vector<Lsb>& start,
                                                   std::uint8_t node);

    /// Handles the frames `bus` delivers within `wait` (at least one wait for the first,
    /// then whatever is already there) and sends the answers; answers the bus refuses
    /// (transmit queue full) wait for the next call. Notices error-passive/bus-off (the node
    /// holds a running device: the link may be gone).
    virtual void serve(hal::CanBus& bus, std::chrono::microseconds wait) = 0;
    /// Batches refused for any reason but a lost data frame (queue full included).
    virtual std::uint32_t refused_batches() const = 0;
    /// Batches refused because a data frame was lost (the host resends them).
    virtual std::uint32_t incomplete_transfers() const = 0;
    virtual std::uint32_t duplicates() const = 0;
    /// Answers dropped because they waited too long for a full transmit queue.
    virtual std::uint64_t answers_dropped() const = 0;
};

/// Serves `bus` and ticks `device` on the steady clock (options.time_scale times real time)
/// until `stop` or options.run_for. Returns the ticks run.
std::uint64_t run_can_device_loop(CanMotionDevice& device, hal::CanBus& bus,
                                  const DeviceLoopOptions& options, const std::atomic<bool>& stop);

}  // namespace pathstream::linux_device
