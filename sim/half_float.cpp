#include "sim/half_float.h"

#include <cmath>
#include <cstring>

#if defined(__x86_64__) || defined(__i386__)
#include <cpuid.h>
#include <immintrin.h>
#endif

namespace siviflow {
namespace {

#if defined(__x86_64__) || defined(__i386__)
// F16C converts 8 floats at once with the same rounding; the tail goes one by one.
__attribute__((target("avx,f16c"))) void to_halves_f16c(std::span<const float> values,
                                                         std::span<uint16_t> halves) {
  size_t i = 0;
  for (; i + 8 <= values.size(); i += 8) {
    const __m256 eight = _mm256_loadu_ps(values.data() + i);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(halves.data() + i),
                     _mm256_cvtps_ph(eight, _MM_FROUND_TO_NEAREST_INT | _MM_FROUND_NO_EXC));
  }
  for (; i < values.size(); ++i) halves[i] = to_half(values[i]);
}

// By CPUID rather than __builtin_cpu_supports, which clang does not ask about F16C: the CPU
// converts (F16C) and runs AVX, and the system saves the AVX registers (XCR0's SSE and AVX bits).
bool cpu_has_f16c() {
  unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
  if (__get_cpuid(1, &eax, &ebx, &ecx, &edx) == 0) return false;
  const unsigned needed = bit_OSXSAVE | bit_AVX | bit_F16C;
  if ((ecx & needed) != needed) return false;
  unsigned xcr0 = 0, xcr0_high = 0;
  __asm__("xgetbv" : "=a"(xcr0), "=d"(xcr0_high) : "c"(0));
  return (xcr0 & 6u) == 6u;
}
#endif

}  // namespace

uint16_t to_half(float value) {
  uint32_t x;
  std::memcpy(&x, &value, sizeof x);
  const uint32_t sign = (x >> 16) & 0x8000u;
  x &= 0x7fffffffu;
  if (x > 0x7f800000u) {  // NaN: quiet, with its payload's top bits (as F16C keeps them)
    return static_cast<uint16_t>(sign | 0x7e00u | ((x >> 13) & 0x3ffu));
  }
  if (x >= 0x477ff000u) return static_cast<uint16_t>(sign | 0x7c00u);  // infinite or past 65504
  if (x < 0x38800000u) {  // below 2^-14: a subnormal half, or zero
    if (x < 0x33000000u) return static_cast<uint16_t>(sign);
    const uint32_t e = x >> 23;
    const uint32_t m = (x & 0x7fffffu) | 0x800000u;
    const uint32_t shift = 126u - e;
    uint32_t h = m >> shift;
    const uint32_t rem = m & ((1u << shift) - 1u), halfway = 1u << (shift - 1u);
    if (rem > halfway || (rem == halfway && (h & 1u))) ++h;
    return static_cast<uint16_t>(sign | h);
  }
  uint32_t h = (x >> 13) - (112u << 10);
  const uint32_t rem = x & 0x1fffu;
  if (rem > 0x1000u || (rem == 0x1000u && (h & 1u))) ++h;  // a carry into the exponent is right
  return static_cast<uint16_t>(sign | h);
}

float from_half(uint16_t bits) {
  const uint32_t sign = (bits & 0x8000u) << 16;
  const uint32_t e = (bits >> 10) & 0x1fu, m = bits & 0x3ffu;
  if (e == 0) {
    const float v = std::ldexp(static_cast<float>(m), -24);
    return sign ? -v : v;
  }
  const uint32_t x =
      e == 31 ? sign | 0x7f800000u | (m << 13) : sign | ((e + 112u) << 23) | (m << 13);
  float f;
  std::memcpy(&f, &x, sizeof f);
  return f;
}

bool to_halves_uses_f16c() {
#if defined(__x86_64__) || defined(__i386__)
  static const bool f16c = cpu_has_f16c();
  return f16c;
#else
  return false;
#endif
}

void to_halves(std::span<const float> values, std::span<uint16_t> halves) {
#if defined(__x86_64__) || defined(__i386__)
  if (to_halves_uses_f16c()) {
    to_halves_f16c(values, halves);
    return;
  }
#endif
  for (size_t i = 0; i < values.size(); ++i) halves[i] = to_half(values[i]);
}

std::vector<uint16_t> halves_of(std::span<const float> values) {
  std::vector<uint16_t> halves(values.size());
  to_halves(values, halves);
  return halves;
}

}  // namespace siviflow
