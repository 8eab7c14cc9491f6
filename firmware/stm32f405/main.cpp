// pathstream on an STM32F405: the device of `pathstream device`, with its Modbus register map
// served over RTU on USART1, ticked by a timer interrupt, driving step/dir, enable, pen, spindle
// and coolant outputs. The split is the core's: the tick interrupt runs the device's tick side
// and the outputs; the main loop is the task, serving the bus, feeding the device's own moves and
// writing the trace. Everything they share is written by one side only (docs/firmware.md,
// "Contexts").
#include <atomic>
#include <cstddef>
#include <cstdint>

#include "board.hpp"
#include "clock.hpp"
#include "firmware.hpp"
#include "pathstream/device/gpio_logic.hpp"
#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/device/motion_device.hpp"
#include "pathstream/device/tick_clock.hpp"
#include "pathstream/hal/machine_lines.hpp"
#include "pathstream/hal/modbus_rtu_slave.hpp"
#include "pathstream/span_queue.hpp"
#include "pins.hpp"
#include "registers.hpp"
#include "step_output.hpp"
#include "switch_inputs.hpp"
#include "trace.hpp"
#include "usart.hpp"

using namespace pathstream;

namespace {

constexpr unsigned kAxes = board::kAxes;
using Device = device::MotionDevice<kAxes, board::kQueueCapacity>;
using RegisterMap = device::ModbusRegisterMap<kAxes, board::kQueueCapacity>;
using ModbusLine = firmware::UsartPort<stm32::kUsart1>;
using Tim2 = stm32::Timer<stm32::kTim2>;
using Tim5 = stm32::Timer<stm32::kTim5>;

/// The tick rate before the host configures one (the machine profiles' usual rate).
constexpr std::uint32_t kDefaultTickHz = 1000;
/// Most ticks one interrupt entry runs; a longer backlog waits for the next entries.
constexpr std::uint32_t kMaxTicksPerEntry = 16;

constexpr Lsb kStart[kAxes] = {};
constexpr firmware::pins::Output kEnableLine{board::kEnable, board::kEnableActiveLow};
constexpr firmware::pins::Output kPenLine{board::kPen, false};
static_assert(hal::OutputLine<firmware::pins::Output>);

// --- owned by init, then by one context each (see the comments) ------------------------------
Device g_device(kStart);
RegisterMap g_map(g_device);                                                         // task
hal::ModbusRtuSlave<RegisterMap> g_slave(g_map, board::kModbusUnit);                 // task
hal::ModbusRtuFramer g_framer(board::kFrameSilenceUs*(board::kTimerHz / 1000000u));  // task
std::uint8_t g_reply[hal::kModbusRtuMaxFrame];                                       // task
firmware::SwitchInputs<kAxes> g_inputs;                                              // task
device::TickClock g_clock;            // tick interrupt
firmware::StepOutput<kAxes> g_steps;  // tick and step interrupts
Lsb g_last[kAxes] = {};               // tick interrupt
std::uint32_t g_positions_set = 0;    // tick interrupt
std::uint64_t g_ticks_executed = 0;   // tick interrupt

/// A byte from the Modbus line and when it came (TIM2 counts).
struct RxByte {
    std::uint8_t byte;
    std::uint32_t at;
};
SpanQueue<RxByte, 512> g_rx;                           // producer: USART1 interrupt; consumer: task
std::atomic<std::uint32_t> g_rx_lost{0};               // USART1 interrupt only
std::atomic<std::uint32_t> g_rx_overruns{0};           // USART1 interrupt only
std::atomic<std::uint32_t> g_tick_hz{kDefaultTickHz};  // task only: the rate it wants
std::atomic<std::uint32_t> g_ticks_dropped{0};         // tick interrupt only: g_clock.dropped()

#ifdef PATHSTREAM_FW_TRACE
firmware::Trace<kAxes> g_trace;        // records: tick interrupt; lines: task
std::int32_t g_steps_reported[kAxes];  // task

// The line's counters, as notes whenever one changes. Task context.
void note_line_counters() {
    static std::uint32_t last[6] = {};
    const std::uint32_t now[6] = {
        g_rx_lost.load(),     g_rx_overruns.load(),          g_slave.counters().bad_crc,
        g_framer.overflows(), g_slave.counters().other_unit, g_ticks_dropped.load()};
    static const char* const names[6] = {"rx_lost",         "rx_overruns", "bad_crc",
                                         "frame_overflows", "other_unit",  "ticks_dropped"};
    for (unsigned k = 0; k < 6; ++k) {
        if (now[k] != last[k]) {
            last[k] = now[k];
            g_trace.note(names[k], now[k], 0);
        }
    }
}
#endif

// The machine functions' pins from the tick's state and outputs (device::machine_output_on),
// in one BSRR write. Tick interrupt, and halt_outputs (all off).
void drive_machine_outputs(device::DeviceState state, std::uint8_t outputs) {
    static_assert(device::kMachineOutputCount ==
                  sizeof board::kMachineOutputPin / sizeof board::kMachineOutputPin[0]);
    std::uint32_t on = 0, off = 0;
    for (unsigned k = 0; k < device::kMachineOutputCount; ++k) {
        const std::uint32_t pin = 1u << board::kMachineOutputPin[k];
        if (device::machine_output_on(state, outputs, device::kMachineOutputBits[k])) {
            on |= pin;
        } else {
            off |= pin;
        }
    }
    firmware::pins::write(board::kMachineOutputPort, on, off);
}

void bump(std::atomic<std::uint32_t>& counter) {
    counter.store(counter.load(std::memory_order_relaxed) + 1, std::memory_order_relaxed);
}

// One device tick and its outputs; `now` is the interrupt's TIM2 count. Tick interrupt. Kept
// out of line: firmware/stm32f405/figures.py counts its instructions per call under qemu.
[[gnu::noinline]] void run_tick(std::uint32_t now) {
    Lsb out[kAxes];
    g_device.tick(out);
    // One copy of the status the tick just wrote (the tick is its writer: no torn read).
    const device::DeviceStatus<kAxes> status = g_device.status();
    const device::DeviceState state = status.device_state();
    const auto outputs = static_cast<std::uint8_t>(status.outputs);
    kEnableLine.set(device::enable_asserted(state));
    kPenLine.set(device::pen_down(state, outputs));
    drive_machine_outputs(state, outputs);
    // A position set at rest ("set zero", homing) moves the coordinates, not the axes: that
    // tick makes no steps.
    const bool moved_coordinates = status.position_applied != g_positions_set;
    g_positions_set = status.position_applied;
    std::int32_t difference[kAxes];
    for (unsigned a = 0; a < kAxes; ++a) {
        difference[a] = moved_coordinates ? 0 : static_cast<std::int32_t>(out[a] - g_last[a]);
        g_last[a] = out[a];
    }
    g_steps.start_tick(difference, now);
    // A path tick (supplied by an accepted span) advances ticks_executed.
    const std::uint64_t executed = status.ticks_executed();
#ifdef PATHSTREAM_FW_TRACE
    if (executed != g_ticks_executed) g_trace.record(out, device::pen_down(state, outputs));
#endif
    g_ticks_executed = executed;
}

// Serves at most one request per pass; after it, publishes the tick rate the host configured
// (the tick takes it at its next entry). Task context.
void serve_bus() {
    // Every byte received so far: a request that more bytes followed before it could be
    // answered is stale (its master timed out and asked again), and the framer lets the newer
    // one replace it, so the master never reads an answer meant for the try it gave up.
    while (const RxByte* r = g_rx.front()) {
        g_framer.on_byte(r->byte, r->at);
        g_rx.release();
    }
    if (!g_framer.poll(Tim2::Cnt::read())) return;
    const std::size_t n = g_slave.handle(g_framer.frame(), g_framer.length(), g_reply);
    g_framer.take();
    if (n != 0) ModbusLine::write(g_reply, n);
    if (g_device.configured() && g_device.limits().tick_hz != g_tick_hz.load()) {
        g_tick_hz.store(g_device.limits().tick_hz);
    }
}

void init_pins() {
    using namespace firmware::pins;
    configure(stm32::kGpioA, 9, stm32::kModeAlternate, 7);   // USART1 TX
    configure(stm32::kGpioA, 10, stm32::kModeAlternate, 7);  // USART1 RX
    configure(stm32::kGpioA, 2, stm32::kModeAlternate, 7);   // USART2 TX (trace)
    firmware::halt_outputs();
    for (unsigned a = 0; a < kAxes; ++a) {
        configure(board::kStepDirPort, board::kStepPin[a], stm32::kModeOutput);
        configure(board::kStepDirPort, board::kDirPin[a], stm32::kModeOutput);
    }
    configure(board::kEnable.port, board::kEnable.number, stm32::kModeOutput);
    configure(board::kPen.port, board::kPen.number, stm32::kModeOutput);
    for (const unsigned pin : board::kMachineOutputPin)
        configure(board::kMachineOutputPort, pin, stm32::kModeOutput);
    if constexpr (board::kSwitchInputs) {
        configure(board::kEstop.port, board::kEstop.number, stm32::kModeInput, 0, stm32::kPullUp);
        for (unsigned k = 0; k < 2 * kAxes; ++k) {
            configure(board::kLimitPort, board::kLimitPinFirst + k, stm32::kModeInput, 0,
                      stm32::kPullUp);
        }
    }
}

// TIM2 counts freely over 32 bits (the time base of the tick, the frames and the step
// pulses); TIM5 interrupts once per tick period. On the qemu model, writing PSC, CNT or EGR
// would reset its time base: only CR1, DIER and ARR are written, in that order.
void init_timers() {
    Tim2::Cr1::write(stm32::kTimCr1Cen);
    Tim2::Arr::write(0xFFFFFFFFu);
    (void)g_clock.start(board::kTimerHz, kDefaultTickHz, Tim2::Cnt::read());
    g_steps.set_period(board::kTimerHz / kDefaultTickHz);
    Tim5::Dier::write(stm32::kTimDierUie);
    Tim5::Cr1::write(stm32::kTimCr1Cen);
    Tim5::Arr::write(board::kTimerHz / kDefaultTickHz - 1u);
    // The receiver first (one byte of buffer), then the step pulses and the tick at one level,
    // so neither preempts the other in the middle of the pulse train.
    stm32::nvic_priority<stm32::kIrqUsart1>(0);
    stm32::nvic_priority<stm32::kIrqTim2>(1);
    stm32::nvic_priority<stm32::kIrqTim5>(1);
    stm32::nvic_enable<stm32::kIrqUsart1>();
    stm32::nvic_enable<stm32::kIrqTim5>();
    if constexpr (firmware::StepOutput<kAxes>::kEnabled) stm32::nvic_enable<stm32::kIrqTim2>();
}

}  // namespace

namespace firmware {

void halt_outputs() {
    g_steps.halt();
    kEnableLine.set(false);
    kPenLine.set(false);
    drive_machine_outputs(device::DeviceState::kIdle, 0);
}

}  // namespace firmware

extern "C" void tim5_irq() {
    Tim5::Sr::write(~stm32::kTimSrUif);  // rc_w0: clears UIF alone
    const std::uint32_t now = Tim2::Cnt::read();
    const std::uint32_t wanted = g_tick_hz.load(std::memory_order_relaxed);
    if (wanted != g_clock.tick_hz() && g_clock.retune(wanted, now)) {
        Tim5::Arr::write(board::kTimerHz / wanted - 1u);
        g_steps.set_period(board::kTimerHz / wanted);
    }
    for (std::uint32_t due = g_clock.advance(now, kMaxTicksPerEntry); due > 0; --due) run_tick(now);
    g_ticks_dropped.store(g_clock.dropped(), std::memory_order_relaxed);
}

extern "C" void usart1_irq() {
    std::uint8_t byte = 0;
    bool overrun = false;
    const bool got = ModbusLine::read(byte, overrun);
    if (overrun) bump(g_rx_overruns);
    if (!got) return;
    RxByte* slot = g_rx.claim();
    if (slot == nullptr) {
        bump(g_rx_lost);
        return;
    }
    *slot = {byte, Tim2::Cnt::read()};
    g_rx.publish();
}

extern "C" void tim2_irq() {
    g_steps.on_compare();
}

int main() {
    firmware::clock_init();
    init_pins();
    ModbusLine::init(board::kUsart1Hz, board::kModbusBaud, true, true);
#ifdef PATHSTREAM_FW_TRACE
    firmware::UsartPort<stm32::kUsart2>::init(board::kUsart2Hz, board::kTraceBaud, false, false);
    g_trace.header(board::kQemu, board::kModbusBaud, board::kModbusUnit);
#endif
    init_timers();
    stm32::enable_interrupts();
    std::uint32_t stack_reported = 0;
    std::uint32_t passes = 0;
    for (;;) {
        serve_bus();
        g_map.service();
        if constexpr (board::kSwitchInputs) g_inputs.poll(g_device);
#ifdef PATHSTREAM_FW_TRACE
        g_trace.drain();
        note_line_counters();
        // At rest, the steps made so far (the test compares them with the setpoints).
        if (g_device.state() == device::DeviceState::kIdle) {
            for (unsigned a = 0; a < kAxes; ++a) {
                const std::int32_t net = g_steps.net_steps(a);
                if (net != g_steps_reported[a]) {
                    g_steps_reported[a] = net;
                    g_trace.note_axis("steps", a, net);
                }
            }
        }
        // The stack's high-water mark, whenever it has grown (a scan every 4096 passes).
        if ((++passes & 4095u) == 0) {
            const std::uint32_t used = firmware::stack_bytes_used();
            if (used > stack_reported) {
                stack_reported = used;
                g_trace.note("stack_used", used, firmware::stack_bytes_total());
            }
        }
#else
        (void)stack_reported;
        (void)passes;
#endif
    }
}
