// The procedural water normal map: layout of the mip chain, unit normals, seamless wrap, a mean
// normal along +Z with real ripples around it, and mips that average the level above.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "water_normal_map.h"

namespace siviflow {
namespace {

// One code of 8-bit UNORM is 2/255 in [-1, 1]; a unit vector rounded per component stays within
// about sqrt(3)/255 of unit length.
constexpr float kQuantisation = 2.0f / 255.0f;

const WaterNormalMap& shared_map() {
  static const WaterNormalMap map = make_water_normal_map();
  return map;
}

glm::vec3 decode(const WaterNormalMap& map, uint32_t level, uint32_t x, uint32_t y) {
  const uint32_t n = map.mip_size(level);
  const uint8_t* t = &map.texels[map.mip_offsets[level] + (size_t{y % n} * n + x % n) * 4];
  return glm::vec3(t[0], t[1], t[2]) / 127.5f - 1.0f;
}

TEST(WaterNormalMap, MipChainLayout) {
  const WaterNormalMap& map = shared_map();
  EXPECT_EQ(map.size, 256u);
  ASSERT_EQ(map.mip_levels, 9u);
  ASSERT_EQ(map.mip_offsets.size(), map.mip_levels);
  size_t expected = 0;
  for (uint32_t level = 0; level < map.mip_levels; ++level) {
    EXPECT_EQ(map.mip_size(level), 256u >> level);
    EXPECT_EQ(map.mip_offsets[level], expected) << "level " << level;
    EXPECT_EQ(map.mip_offsets[level] % 4, 0u) << "texels are 4-byte aligned for the copy";
    expected += size_t{map.mip_size(level)} * map.mip_size(level) * 4;
  }
  EXPECT_EQ(map.mip_size(map.mip_levels - 1), 1u);
  EXPECT_EQ(map.texels.size(), expected);
}

TEST(WaterNormalMap, IsDeterministic) {
  const WaterNormalMap again = make_water_normal_map();
  EXPECT_EQ(again.texels, shared_map().texels);
  EXPECT_EQ(again.mip_offsets, shared_map().mip_offsets);
}

TEST(WaterNormalMap, DecodedNormalsAreUnitLengthAndFaceUp) {
  const WaterNormalMap& map = shared_map();
  for (uint32_t level = 0; level < map.mip_levels; ++level) {
    const uint32_t n = map.mip_size(level);
    float worst = 0.0f;
    float min_z = 1.0f;
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        const glm::vec3 normal = decode(map, level, x, y);
        worst = std::max(worst, std::abs(glm::length(normal) - 1.0f));
        min_z = std::min(min_z, normal.z);
      }
    }
    EXPECT_LT(worst, kQuantisation) << "level " << level;
    EXPECT_GT(min_z, 0.3f) << "level " << level << ": no ripple is steeper than ~70 degrees";
  }
}

// Across the wrap (last column -> first, last row -> first) the first and second differences of
// the normal must look like those inside; a seam shows as a jump many times the interior step.
struct SeamStats {
  double interior_step = 0.0;  // mean |n(i+1) - n(i)| over interior neighbours
  double seam_step = 0.0;      // the same across the wrap
  double max_interior_step = 0.0;
  double max_seam_step = 0.0;
  double interior_bend = 0.0;  // mean |n(i-1) - 2 n(i) + n(i+1)|
  double seam_bend = 0.0;      // at i = 0 and i = size - 1, using the wrapped neighbour
};

SeamStats seam_stats(const WaterNormalMap& map, uint32_t level, bool across_columns) {
  const uint32_t n = map.mip_size(level);
  auto at = [&](uint32_t along, uint32_t line) {
    return across_columns ? decode(map, level, along, line) : decode(map, level, line, along);
  };
  SeamStats s;
  size_t interior = 0;
  size_t interior_bends = 0;
  for (uint32_t line = 0; line < n; ++line) {
    for (uint32_t i = 0; i < n; ++i) {
      const double step = glm::length(at(i + 1, line) - at(i, line));  // i + 1 wraps at n - 1
      const double bend =
          glm::length(at(i + n - 1, line) - 2.0f * at(i, line) + at(i + 1, line));
      if (i == n - 1) {
        s.seam_step += step;
        s.max_seam_step = std::max(s.max_seam_step, step);
      } else {
        s.interior_step += step;
        s.max_interior_step = std::max(s.max_interior_step, step);
        ++interior;
      }
      if (i == 0 || i == n - 1) {
        s.seam_bend += bend;
      } else {
        s.interior_bend += bend;
        ++interior_bends;
      }
    }
  }
  s.interior_step /= static_cast<double>(interior);
  s.seam_step /= static_cast<double>(n);
  s.interior_bend /= static_cast<double>(interior_bends);
  s.seam_bend /= static_cast<double>(2 * n);
  return s;
}

TEST(WaterNormalMap, TilesWithoutSeams) {
  const WaterNormalMap& map = shared_map();
  for (uint32_t level = 0; level < 4; ++level) {
    for (bool across_columns : {true, false}) {
      const SeamStats s = seam_stats(map, level, across_columns);
      SCOPED_TRACE(testing::Message() << "level " << level
                                      << (across_columns ? " left/right" : " top/bottom"));
      ASSERT_GT(s.interior_step, 4.0 * kQuantisation) << "the test needs a visible gradient";
      EXPECT_GT(s.seam_step, 0.6 * s.interior_step);
      EXPECT_LT(s.seam_step, 1.4 * s.interior_step);
      EXPECT_LE(s.max_seam_step, s.max_interior_step);
      EXPECT_LT(s.seam_bend, 1.4 * s.interior_bend + kQuantisation);
    }
  }
}

TEST(WaterNormalMap, MeanNormalIsUpWithRipplesAroundIt) {
  const WaterNormalMap& map = shared_map();
  const uint32_t n = map.size;
  glm::dvec3 sum(0.0);
  glm::dvec3 sum_sq(0.0);
  for (uint32_t y = 0; y < n; ++y) {
    for (uint32_t x = 0; x < n; ++x) {
      const glm::dvec3 normal(decode(map, 0, x, y));
      sum += normal;
      sum_sq += normal * normal;
    }
  }
  const double count = static_cast<double>(n) * n;
  const glm::dvec3 mean = sum / count;
  const glm::dvec3 deviation = glm::sqrt(sum_sq / count - mean * mean);
  EXPECT_LT(std::abs(mean.x), 0.02);
  EXPECT_LT(std::abs(mean.y), 0.02);
  EXPECT_GT(mean.z, 0.8);
  EXPECT_GT(deviation.x, 0.15) << "ripples must tilt the normal, not leave it flat";
  EXPECT_GT(deviation.y, 0.1);
  // The 1x1 mip is the whole map's average: close to straight up.
  EXPECT_GT(decode(map, map.mip_levels - 1, 0, 0).z, 0.98f);
}

TEST(WaterNormalMap, MipsAverageTheLevelAboveAndFlattenIt) {
  const WaterNormalMap& map = shared_map();
  double previous_mean_z = 0.0;
  for (uint32_t level = 0; level < map.mip_levels; ++level) {
    const uint32_t n = map.mip_size(level);
    double mean_z = 0.0;
    float worst = 0.0f;
    for (uint32_t y = 0; y < n; ++y) {
      for (uint32_t x = 0; x < n; ++x) {
        const glm::vec3 normal = decode(map, level, x, y);
        mean_z += normal.z;
        if (level == 0) continue;
        const glm::vec3 average =
            glm::normalize(decode(map, level - 1, 2 * x, 2 * y) + decode(map, level - 1, 2 * x + 1, 2 * y) +
                           decode(map, level - 1, 2 * x, 2 * y + 1) +
                           decode(map, level - 1, 2 * x + 1, 2 * y + 1));
        worst = std::max(worst, glm::length(normal - average));
      }
    }
    mean_z /= static_cast<double>(n) * n;
    // Each level is built from the float level above, not its bytes: allow two quantisations.
    EXPECT_LT(worst, 2.0f * kQuantisation) << "level " << level;
    EXPECT_GE(mean_z, previous_mean_z - 1e-3) << "level " << level << " should be flatter";
    previous_mean_z = mean_z;
  }
}

}  // namespace
}  // namespace siviflow
