// The board the image is built for: clocks, the pin map, the bus settings. Two profiles share
// every other line of the image:
//   silicon (default)  an STM32F405/407 with an 8 MHz crystal, run at 168 MHz from the PLL;
//   qemu               `qemu-system-arm -M netduinoplus2` (PATHSTREAM_FW_QEMU): no clock setup
//                      (the model's RCC never reports ready), its timers count at 1 GHz
//                      whatever RCC says, and it has no GPIO model (inputs read 0, so the
//                      switch inputs are left out).
// To move a function to another pin, change its entry in the pin map below (docs/firmware.md,
// "Pin map"); the step and direction pins of all axes stay on one port so that one BSRR write
// raises every step of a pulse.
#pragma once

#include <cstdint>

#include "registers.hpp"

namespace board {

#ifdef PATHSTREAM_FW_QEMU
inline constexpr bool kQemu = true;
inline constexpr std::uint32_t kTimerHz = 1000000000u;  ///< TIM2 and TIM5 count (the model)
inline constexpr std::uint32_t kUsart1Hz = 84000000u;   ///< BRR is ignored by the model
inline constexpr std::uint32_t kUsart2Hz = 42000000u;
#else
inline constexpr bool kQemu = false;
inline constexpr std::uint32_t kHseHz = 8000000u;
inline constexpr std::uint32_t kCpuHz = 168000000u;
inline constexpr std::uint32_t kTimerHz = 84000000u;   ///< APB1 42 MHz, timers at twice it
inline constexpr std::uint32_t kUsart1Hz = 84000000u;  ///< APB2
inline constexpr std::uint32_t kUsart2Hz = 42000000u;  ///< APB1
#endif

#ifndef PATHSTREAM_FW_AXES
#define PATHSTREAM_FW_AXES 2
#endif
/// Axes the image drives (a build option: 1 to 4 with the pin map below).
inline constexpr unsigned kAxes = PATHSTREAM_FW_AXES;
static_assert(kAxes >= 1 && kAxes <= 4, "the pin map has step/dir pins for four axes");

/// Spans the device queues (the Linux device's Modbus capacity).
inline constexpr std::uint32_t kQueueCapacity = 64;

// --- The Modbus line (USART1: TX PA9, RX PA10, AF7), 8E1 as the serial-line spec's default ----
inline constexpr std::uint32_t kModbusBaud = 115200;
inline constexpr std::uint8_t kModbusUnit = 1;
/// The silence that ends a frame: the spec's t3.5 on a board; under qemu a pty feeds the model
/// byte by byte at the host's pace, so a request (which ends by its length and CRC anyway, see
/// ModbusRtuFramer) gets more room before a pause inside it would cut it.
inline constexpr std::uint32_t kFrameSilenceUs = kQemu ? 50000u : 1750u;

// --- The trace line (USART2: TX PA2, AF7), when built with PATHSTREAM_FW_TRACE -----------------
inline constexpr std::uint32_t kTraceBaud = 1000000;

/// One output or input pin: its port's base address and its number on the port.
struct Pin {
    std::uintptr_t port;
    unsigned number;
};

// --- The pin map
// ----------------------------------------------------------------------------------
/// Step and direction of axes 0..3 (x, y, z, a): PD0/PD1, PD2/PD3, PD4/PD5, PD6/PD7.
inline constexpr std::uintptr_t kStepDirPort = stm32::kGpioD;
inline constexpr unsigned kStepPin[4] = {0, 2, 4, 6};
inline constexpr unsigned kDirPin[4] = {1, 3, 5, 7};
/// Drive enable (PD8, active low as on most step/dir drivers) and pen lift (PD9, active high).
inline constexpr Pin kEnable = {stm32::kGpioD, 8};
inline constexpr bool kEnableActiveLow = true;
inline constexpr Pin kPen = {stm32::kGpioD, 9};
/// The machine functions, high = on (relay or VFD inputs through a driver): spindle runs
/// (PD10), spindle counter-clockwise (PD11), mist (PD12), flood (PD13), in the order of
/// device::kMachineOutputBits. One port, so that one BSRR write switches them together.
inline constexpr std::uintptr_t kMachineOutputPort = stm32::kGpioD;
inline constexpr unsigned kMachineOutputPin[4] = {10, 11, 12, 13};
/// E-stop (PE0) and limit switches x-, x+, y-, y+, ... (PE1..PE8), active low with pull-ups:
/// a broken wire reads as pressed.
inline constexpr Pin kEstop = {stm32::kGpioE, 0};
inline constexpr std::uintptr_t kLimitPort = stm32::kGpioE;
inline constexpr unsigned kLimitPinFirst = 1;  ///< axis a, side s (0 -, 1 +): PE(1 + 2a + s)
inline constexpr bool kSwitchInputs = !kQemu;

// --- Step pulses
// ----------------------------------------------------------------------------------
/// The drivers' minimum step pulse width and direction setup, in timer counts (2 us and 1 us
/// at the silicon timer clock; common figures for DRV8825/TMC2209-class drivers).
inline constexpr std::uint32_t kStepPulseCounts = kTimerHz / 500000u;
inline constexpr std::uint32_t kDirSetupCounts = kTimerHz / 1000000u;

}  // namespace board
