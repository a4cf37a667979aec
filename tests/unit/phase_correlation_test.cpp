// The ripple-motion test's phase correlation finds known shifts of a smooth random pattern, to a
// fraction of a pixel, with a far higher peak than between unrelated patterns.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "phase_correlation.h"

namespace siviflow::testing {
namespace {

// A random field with a broad spectrum, as ripples have (a sum of many random waves), sampled
// at (x + dx, y + dy).
struct Waves {
  explicit Waves(unsigned seed) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (auto& w : waves) {
      const double angle = 2.0 * std::numbers::pi * unit(random);
      const double length = 4.0 + 10.0 * unit(random);  // pixels per wave
      w = {std::cos(angle) / length, std::sin(angle) / length, 2.0 * std::numbers::pi * unit(random)};
    }
  }
  Window window(size_t size, double dx, double dy) const {
    Window out{size, {std::vector<double>(size * size)}};
    for (size_t y = 0; y < size; ++y) {
      for (size_t x = 0; x < size; ++x) {
        double v = 0.0;
        for (const auto& w : waves) {
          v += std::sin(2.0 * std::numbers::pi * (w.kx * (x + dx) + w.ky * (y + dy)) + w.phase);
        }
        out.channels[0][y * size + x] = v;
      }
    }
    return out;
  }
  struct Wave {
    double kx, ky, phase;
  };
  Wave waves[200];
};

TEST(PhaseCorrelationTest, FindsSubpixelShifts) {
  const Waves pattern(3);
  const glm::dvec2 shifts[] = {{0.0, 0.0}, {3.0, -2.0}, {2.4, 1.7}, {-5.3, 0.6}, {0.3, -6.8}};
  for (const glm::dvec2 shift : shifts) {
    // The second window sees the pattern moved by +shift: second(p) = first(p - shift).
    double peak = 0.0;
    const glm::dvec2 found = phase_correlation_shift(pattern.window(32, 0.0, 0.0),
                                                     pattern.window(32, -shift.x, -shift.y), &peak);
    EXPECT_NEAR(found.x, shift.x, 0.05 * std::abs(shift.x) + 0.1) << shift.x << ", " << shift.y;
    EXPECT_NEAR(found.y, shift.y, 0.05 * std::abs(shift.y) + 0.1) << shift.x << ", " << shift.y;
    double unrelated = 0.0;
    phase_correlation_shift(pattern.window(32, 0.0, 0.0), Waves(4).window(32, -shift.x, -shift.y),
                            &unrelated);
    EXPECT_GT(peak, 2.0 * unrelated) << "a shifted pattern correlates, another does not";
  }
}

}  // namespace
}  // namespace siviflow::testing
