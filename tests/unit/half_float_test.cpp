// Half floats: the scalar conversion rounds to nearest even, and the bulk conversion (F16C where
// the CPU has it) gives the same bits for every kind of value.
#include "sim/half_float.h"

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

namespace siviflow {
namespace {

TEST(HalfFloat, RoundsToNearestEven) {
  EXPECT_EQ(to_half(0.0f), 0x0000);
  EXPECT_EQ(to_half(-0.0f), 0x8000);
  EXPECT_EQ(to_half(1.0f), 0x3c00);
  EXPECT_EQ(to_half(-2.0f), 0xc000);
  EXPECT_EQ(to_half(65504.0f), 0x7bff);
  EXPECT_EQ(to_half(65519.0f), 0x7bff);
  EXPECT_EQ(to_half(65520.0f), 0x7c00);  // the tie rounds to even: infinity
  EXPECT_EQ(to_half(std::numeric_limits<float>::infinity()), 0x7c00);
  EXPECT_EQ(to_half(std::nanf("")) & 0x7c00, 0x7c00);
  EXPECT_NE(to_half(std::nanf("")) & 0x03ff, 0);
  EXPECT_EQ(to_half(std::ldexp(1.0f, -24)), 0x0001);  // smallest subnormal
  EXPECT_EQ(to_half(std::ldexp(1.0f, -25)), 0x0000);  // tie to even
  EXPECT_EQ(to_half(1.0f + std::ldexp(1.0f, -11)), 0x3c00);  // tie to even (down)
  EXPECT_EQ(to_half(1.0f + 3.0f * std::ldexp(1.0f, -11)), 0x3c02);  // tie to even (up)
  // Every half round-trips, and a float rounds to the nearest half (checked in double).
  for (uint32_t h = 0; h < 0x7c00; ++h) {
    const float f = from_half(static_cast<uint16_t>(h));
    ASSERT_EQ(to_half(f), h);
    ASSERT_EQ(to_half(-f), h | 0x8000u);
    if (h + 1 < 0x7c00) {
      const double mid = 0.5 * (double(f) + double(from_half(static_cast<uint16_t>(h + 1))));
      const float below = std::nextafter(static_cast<float>(mid), 0.0f);
      if (static_cast<double>(below) < mid) {
        ASSERT_EQ(to_half(below), h);
      }
    }
  }
}

TEST(HalfFloat, BulkConversionGivesTheScalarBits) {
  // An odd stride walks all exponents, subnormals, infinities and NaN
  // payloads; an odd count leaves a tail after the 8-wide blocks.
  std::vector<float> values;
  for (uint64_t bits = 0; bits <= 0xffffffffu; bits += 4093) {
    values.push_back(std::bit_cast<float>(static_cast<uint32_t>(bits)));
  }
  values.push_back(65520.0f);
  values.push_back(-std::numeric_limits<float>::infinity());
  values.push_back(std::ldexp(1.0f, -25));
  ASSERT_NE(values.size() % 8, 0u);
  std::vector<uint16_t> halves(values.size());
  SCOPED_TRACE(to_halves_uses_f16c() ? "with F16C" : "one value at a time (no F16C here)");
  to_halves(values, halves);
  for (size_t i = 0; i < values.size(); ++i) {
    ASSERT_EQ(halves[i], to_half(values[i]))
        << "float bits 0x" << std::hex << std::bit_cast<uint32_t>(values[i]);
  }
}

TEST(HalfFloat, NanKeepsItsSignAndPayloadTopBits) {
  EXPECT_EQ(to_half(std::bit_cast<float>(0x7fc00000u)), 0x7e00);
  EXPECT_EQ(to_half(std::bit_cast<float>(0xffc02000u)), 0xfe01);
  EXPECT_EQ(to_half(std::bit_cast<float>(0x7f802000u)), 0x7e01);  // signalling: made quiet
}

}  // namespace
}  // namespace siviflow
