// What the image's files share: the few functions one file defines and another calls.
#pragma once

#include <cstdint>

namespace firmware {

/// Drives every output to its safe level at once: enable inactive, pen up, spindle and coolant
/// off, step pins low, step timer stopped. Any context (the fault handler calls it with
/// interrupts off).
void halt_outputs();

/// Bytes of the main stack ever used (the highest point not still painted at reset) and the
/// stack's size (__stack_size). Any context; a scan of the stack, so call it rarely.
std::uint32_t stack_bytes_used();
std::uint32_t stack_bytes_total();

}  // namespace firmware
