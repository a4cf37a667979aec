// Numbers from the fuzzer's bytes, biased towards what breaks geometry code: zero, the largest
// finite floats, the world limit and just past it, denormals, tiny and huge scales, and now and
// then a NaN or an infinity; otherwise ordinary values in a range, so that most inputs still
// reach deep into the code.
#pragma once

#include <cstdint>
#include <limits>

#include <fuzzer/FuzzedDataProvider.h>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace siviflow::fuzzing {

// `finite`: never a NaN or an infinity (for calls whose callers check those first).
inline float extreme_or(FuzzedDataProvider& in, float lo, float hi, bool finite = false) {
  using limits = std::numeric_limits<float>;
  const float sign = in.ConsumeBool() ? 1.0f : -1.0f;
  switch (in.ConsumeIntegralInRange<int>(0, 15)) {
    case 0: return 0.0f;
    case 1: return sign * limits::max();
    case 2: return sign * 3.4e38f;
    case 3: return sign * 1.0e6f;     // the world limit (siviflow/sim/world_limits.h)
    case 4: return sign * 1.0000001e6f;
    case 5: return sign * limits::denorm_min() * static_cast<float>(in.ConsumeIntegral<uint16_t>());
    case 6: return sign * limits::min();
    case 7: return sign * limits::epsilon();
    case 8:
      if (finite) return sign * limits::max();
      return in.ConsumeBool() ? limits::quiet_NaN() : sign * limits::infinity();
    case 9: return sign * 1.0e20f;
    default: return in.ConsumeFloatingPointInRange<float>(lo, hi);
  }
}

// Mostly `usual` (so that a mesh stays a mesh), sometimes anything extreme_or gives.
inline float mostly(FuzzedDataProvider& in, float usual, float lo, float hi) {
  return in.ConsumeIntegralInRange<int>(0, 7) == 0 ? extreme_or(in, lo, hi) : usual;
}

inline glm::vec3 extreme_vec3(FuzzedDataProvider& in, float lo, float hi, bool finite = false) {
  const float x = extreme_or(in, lo, hi, finite);
  const float y = extreme_or(in, lo, hi, finite);
  return {x, y, extreme_or(in, lo, hi, finite)};
}

inline glm::vec2 extreme_vec2(FuzzedDataProvider& in, float lo, float hi, bool finite = false) {
  const float x = extreme_or(in, lo, hi, finite);
  return {x, extreme_or(in, lo, hi, finite)};
}

}  // namespace siviflow::fuzzing
