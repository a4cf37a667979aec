// IEEE 754 binary16 ("half") conversions, rounding to nearest even: the flow texture's texels,
// the capture's HALF layers and a river's depth and slope per vertex.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace siviflow {

inline constexpr float kLargestHalf = 65504.0f;  // binary16's largest finite value

uint16_t to_half(float value);
float from_half(uint16_t bits);

// Converts `values` into `halves` (of the same size), bit for bit as to_half does each value, with
// the CPU's conversion instructions where it has them: a frame's planes convert in a few ms.
void to_halves(std::span<const float> values, std::span<uint16_t> halves);
// Whether to_halves uses those instructions on this CPU (else it converts one value at a time).
bool to_halves_uses_f16c();

// Values kept as binary16 bits and read as floats: what a long river keeps a vertex of at the
// precision its textures carry (the paper's auxiliary texture holds depth and slope in 8 bits).
class HalfValues {
 public:
  HalfValues() = default;
  HalfValues(std::span<const uint16_t> bits) : bits_(bits) {}     // NOLINT: a view, as span is
  HalfValues(const std::vector<uint16_t>& bits) : bits_(bits) {}  // NOLINT: as above
  HalfValues(std::vector<uint16_t>&&) = delete;                   // it would dangle
  float operator[](size_t i) const { return from_half(bits_[i]); }
  size_t size() const { return bits_.size(); }
  bool empty() const { return bits_.empty(); }
  HalfValues first(size_t count) const { return HalfValues(bits_.first(count)); }

 private:
  std::span<const uint16_t> bits_;
};

// `values` as binary16 (to_halves' rounding).
std::vector<uint16_t> halves_of(std::span<const float> values);

}  // namespace siviflow
