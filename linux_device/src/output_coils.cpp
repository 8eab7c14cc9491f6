#include "pathstream/linux_device/output_coils.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <stdexcept>
#include <utility>

#include "pathstream/hal/modbus_error.hpp"
#include "pathstream/hal/modbus_target.hpp"

namespace pathstream::linux_device {

static_assert(host::kMachineFunctionCount == device::kMachineOutputCount,
              "the profile's machine functions are the device's machine outputs, in one order");

namespace {

hal::ModbusTarget checked_target(const host::OutputCoilsConfig& config) {
    if (!config.present) throw std::invalid_argument("the profile has no \"output_coils\" object");
    bool any = false;
    for (const std::int32_t c : config.coil) any = any || c >= 0;
    if (!any) throw std::invalid_argument("output_coils maps no coil");
    return hal::parse_modbus_target(config.target);
}

// "spindle (coil 0) on": one coil of a write, for its error message.
std::string describe(const OutputCoil& c, bool on) {
    return std::string(c.function) + " (coil " + std::to_string(c.address) + ")" +
           (on ? " on" : " off");
}

}  // namespace

std::vector<OutputCoil> output_coil_list(const host::OutputCoilsConfig& config) {
    std::vector<OutputCoil> out;
    for (unsigned k = 0; k < host::kMachineFunctionCount; ++k) {
        if (config.coil[k] < 0) continue;
        out.push_back(OutputCoil{host::kMachineFunctionKeys[k], device::kMachineOutputBits[k],
                                 static_cast<std::uint16_t>(config.coil[k])});
    }
    std::sort(out.begin(), out.end(),
              [](const OutputCoil& a, const OutputCoil& b) { return a.address < b.address; });
    return out;
}

hal::ModbusClientOptions output_coil_client_options() {
    hal::ModbusClientOptions o;
    o.response_timeout = std::chrono::milliseconds(500);
    o.byte_timeout = std::chrono::milliseconds(500);
    o.attempts = 2;
    return o;
}

CoilWriter::CoilWriter(const host::OutputCoilsConfig& config,
                       const hal::ModbusClientOptions& options)
    : client_(checked_target(config), options), coils_(output_coil_list(config)) {
    for (const OutputCoil& c : coils_) mapped_ = static_cast<std::uint8_t>(mapped_ | c.bit);
}

std::string CoilWriter::target() const {
    return hal::to_string(client_.target());
}

std::string CoilWriter::mapping() const {
    std::string out;
    for (const OutputCoil& c : coils_)
        out += (out.empty() ? "" : " ") + std::string(c.function) + "=" + std::to_string(c.address);
    return out;
}

void CoilWriter::apply(std::uint8_t outputs) {
    outputs = static_cast<std::uint8_t>(outputs & mapped_);
    const std::uint8_t changed = known_ ? static_cast<std::uint8_t>(outputs ^ written_) : mapped_;
    if (changed == 0) return;
    known_ = false;  // until the module has confirmed every write below
    std::vector<const OutputCoil*> group;
    for (const OutputCoil& c : coils_) {
        if ((changed & c.bit) != 0) group.push_back(&c);
    }
    // The mapped coils from the first changed one to the last, in address order: one FC15 when
    // they sit at consecutive addresses (the unchanged ones among them are written with the
    // value they have: written_ == outputs for them).
    const auto first = static_cast<std::size_t>(group.front() - coils_.data());
    const auto last = static_cast<std::size_t>(group.back() - coils_.data());
    const auto spread = static_cast<std::size_t>(coils_[last].address - coils_[first].address);
    if (group.size() > 1 && spread == last - first) {
        std::vector<const OutputCoil*> range;
        for (std::size_t k = first; k <= last; ++k) range.push_back(&coils_[k]);
        write_group(range, outputs);
    } else {
        // Off first, the spindle's before the others; then on, the spindle's after the others.
        const auto spindle_first = [](const OutputCoil* a, const OutputCoil* b) {
            return (a->bit == kOutputSpindle) > (b->bit == kOutputSpindle);
        };
        std::vector<const OutputCoil*> off, on;
        for (const OutputCoil* c : group) ((outputs & c->bit) != 0 ? on : off).push_back(c);
        std::stable_sort(off.begin(), off.end(), spindle_first);
        std::stable_sort(on.begin(), on.end(), [&](const OutputCoil* a, const OutputCoil* b) {
            return spindle_first(b, a);
        });
        for (const OutputCoil* c : off) write_one(*c, false);
        for (const OutputCoil* c : on) write_one(*c, true);
    }
    written_ = outputs;
    known_ = true;
}

void CoilWriter::write_group(const std::vector<const OutputCoil*>& group, std::uint8_t outputs) {
    std::vector<std::uint8_t> values;
    std::string what;
    for (const OutputCoil* c : group) {
        const bool on = (outputs & c->bit) != 0;
        values.push_back(on ? 1 : 0);
        what += (what.empty() ? "" : ", ") + describe(*c, on);
    }
    try {
        client_.write_coils(group.front()->address, values);
    } catch (const hal::ModbusError& e) {
        fail(e, what);
    }
}

void CoilWriter::write_one(const OutputCoil& coil, bool on) {
    try {
        client_.write_coil(coil.address, on);
    } catch (const hal::ModbusError& e) {
        fail(e, describe(coil, on));
    }
}

void CoilWriter::fail(const hal::ModbusError& e, const std::string& what) const {
    // "<target>: cannot switch flood (coil 3) on: FC5 write coil 3 on: timeout (...)": the
    // client's message starts with the target too; it is said once.
    const std::string prefix = target() + ": ";
    std::string reason = e.what();
    if (reason.compare(0, prefix.size(), prefix) == 0) reason.erase(0, prefix.size());
    throw hal::ModbusError(e.kind(), prefix + "cannot switch " + what + ": " + reason,
                           e.exception_code(), e.os_error());
}

OutputCoilThread::OutputCoilThread(CoilWriter writer)
    : writer_(std::move(writer)), target_(writer_.target()), mapping_(writer_.mapping()) {
    writer_.apply(0);  // throws before any thread exists
    thread_ = std::thread([this] { run(); });
}

OutputCoilThread::~OutputCoilThread() {
    (void)stop();
}

void OutputCoilThread::publish(std::uint8_t outputs) {
    if (stopped_ || outputs == published_) return;
    published_ = outputs;
    wanted_.store(outputs, std::memory_order_release);
    // The writer holds the mutex only to test wanted_ and go to sleep (never while it writes):
    // taking it here orders this store before that test or after the sleep began, so the
    // wake-up cannot be lost.
    { const std::lock_guard<std::mutex> lock(mutex_); }
    wake_.notify_one();
}

bool OutputCoilThread::take_failure(std::string& message) {
    const std::uint32_t n = failures_.load(std::memory_order_acquire);
    if (n == failures_seen_) return false;
    failures_seen_ = n;
    const std::lock_guard<std::mutex> lock(mutex_);
    message = failure_text_;
    return true;
}

std::string OutputCoilThread::stop() {
    if (stopped_) return "";
    stopped_ = true;
    if (thread_.joinable()) {
        wanted_.store(published_ | kStop, std::memory_order_release);
        { const std::lock_guard<std::mutex> lock(mutex_); }
        wake_.notify_one();
        thread_.join();
    }
    try {
        writer_.forget();  // every coil, whatever the module was last told
        writer_.apply(0);
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

void OutputCoilThread::run() {
    std::uint32_t handled = 0;  // all off: written before the thread started
    for (;;) {
        std::uint32_t want = 0;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return wanted_.load(std::memory_order_acquire) != handled; });
            want = wanted_.load(std::memory_order_acquire);
        }
        if ((want & kStop) != 0) return;
        // A failed value is not tried again by itself: the next change writes every coil
        // (the writer forgot their state), and the device is stopped meanwhile.
        handled = want;
        std::string failure;
        try {
            writer_.apply(static_cast<std::uint8_t>(want));
            writes_.fetch_add(1, std::memory_order_release);
            continue;
        } catch (const std::exception& e) {
            failure = e.what();
        }
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            failure_text_ = failure;
        }
        failures_.fetch_add(1, std::memory_order_release);
    }
}

}  // namespace pathstream::linux_device
