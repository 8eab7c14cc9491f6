// The system clock: 168 MHz from the PLL on a board, nothing under qemu (the model's RCC never
// reports ready and its timers count at 1 GHz whatever RCC says).
#pragma once

namespace firmware {

/// Sets flash wait states, starts the crystal (or falls back to the internal 16 MHz
/// oscillator when the crystal does not start), the PLL (168 MHz core, 42 MHz APB1, 84 MHz
/// APB2, 48 MHz for USB) and switches to it; enables the clocks of the peripherals the image
/// uses. Init context, once, first thing in main().
void clock_init();

}  // namespace firmware
