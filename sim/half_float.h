// IEEE 754 binary16 ("half") conversions, rounding to nearest even: the flow texture's texels and
// the capture's HALF layers.
#pragma once

#include <cstdint>
#include <span>

namespace siviflow {

uint16_t to_half(float value);
float from_half(uint16_t bits);

// Converts `values` into `halves` (of the same size), bit for bit as to_half does each value, with
// the CPU's conversion instructions where it has them: a frame's planes convert in a few ms.
void to_halves(std::span<const float> values, std::span<uint16_t> halves);
// Whether to_halves uses those instructions on this CPU (else it converts one value at a time).
bool to_halves_uses_f16c();

}  // namespace siviflow
