#include "pathstream/linux_device/can_motion_device.hpp"

#include <deque>
#include <stdexcept>

#include "pathstream/device/can_node.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/machine/core_span_conversion.hpp"

namespace pathstream::linux_device {
namespace {

namespace pc = device::can;

hal::CanFrame to_hal(const pc::Frame& f) {
    hal::CanFrame h;
    h.id = f.id;
    h.length = f.length;
    for (unsigned i = 0; i < 8; ++i) h.data[i] = f.data[i];
    return h;
}

template <unsigned Axes>
class Device final : public MotionDeviceBase<Axes, kCanDeviceCapacity, CanMotionDevice> {
public:
    Device(const Lsb (&start)[Axes], std::uint8_t node)
        : MotionDeviceBase<Axes, kCanDeviceCapacity, CanMotionDevice>(start),
          node_(this->device_, node) {}

    // The task's share of every loop turn comes first: a jog in progress is fed.
    void connect_homing(const device::HomingPort& port) override {
        node_.operator_commands().set_homing(port);
    }

    void tick() override {
        node_.service();
        MotionDeviceBase<Axes, kCanDeviceCapacity, CanMotionDevice>::tick();
    }

    void serve(hal::CanBus& bus, std::chrono::microseconds wait) override {
        flush(bus);
        const hal::CanBusState s = bus.state();
        if (s >= hal::CanBusState::kErrorPassive && last_state_ < hal::CanBusState::kErrorPassive)
            node_.link_lost();
        last_state_ = s;
        hal::CanFrame in;
        auto send = [&](const pc::Frame& f) { pending_.push_back(to_hal(f)); };
        std::uint32_t timeout = static_cast<std::uint32_t>(wait.count() > 0 ? wait.count() : 0);
        while (bus.receive(in, timeout)) {
            timeout = 0;
            if (in.extended || in.remote) continue;
            pc::Frame f;
            f.id = in.id;
            f.length = in.length;
            for (unsigned i = 0; i < 8; ++i) f.data[i] = in.data[i];
            node_.handle(f, send);
            flush(bus);
        }
    }

    std::uint32_t refused_batches() const override { return node_.refused_batches(); }
    std::uint32_t incomplete_transfers() const override { return node_.incomplete_transfers(); }
    std::uint32_t duplicates() const override { return this->device_.duplicates(); }
    std::uint64_t answers_dropped() const override { return dropped_; }

private:
    // Sends what waits; a full transmit queue keeps the rest for later, a bus-off drops it
    // (stale answers are worthless once the bus is back: the host asks again).
    void flush(hal::CanBus& bus) {
        while (!pending_.empty()) {
            const hal::CanSendResult r = bus.send(pending_.front());
            if (r == hal::CanSendResult::kQueueFull) return;
            if (r != hal::CanSendResult::kQueued) ++dropped_;
            pending_.pop_front();
        }
    }

    pc::CanNode<Axes, kCanDeviceCapacity> node_;
    std::deque<hal::CanFrame> pending_;
    hal::CanBusState last_state_ = hal::CanBusState::kErrorActive;
    std::uint64_t dropped_ = 0;
};

}  // namespace

std::unique_ptr<CanMotionDevice> CanMotionDevice::create(const std::vector<Lsb>& start,
                                                         std::uint8_t node) {
    if (node < pc::kMinNode || node > pc::kMaxNode) {
        throw std::invalid_argument("CAN node id " + std::to_string(node) + " is outside 1..127");
    }
    return host::with_axes(start.size(), [&](auto axes) -> std::unique_ptr<CanMotionDevice> {
        constexpr unsigned A = decltype(axes)::value;
        Lsb s[A];
        for (unsigned a = 0; a < A; ++a) s[a] = start[a];
        return std::make_unique<Device<A>>(s, node);
    });
}

std::uint64_t run_can_device_loop(CanMotionDevice& device, hal::CanBus& bus,
                                  const DeviceLoopOptions& options, const std::atomic<bool>& stop) {
    return run_paced_loop([&] { device.tick(); }, [&] { return device.tick_hz(); },
                          [&](std::chrono::microseconds wait) { device.serve(bus, wait); }, options,
                          stop);
}

}  // namespace pathstream::linux_device
