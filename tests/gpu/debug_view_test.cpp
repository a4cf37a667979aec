// The water's debug views show what the material reads: the flow view's hue is the direction of
// the flow texel under each pixel, the particles view gives each particle's pixels one colour of
// their own, the tile grid only draws lines over the look; none of them touches the AOVs, and
// switching back gives the look bit for bit.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "render_frames.h"
#include "shaders/shared.h"

namespace siviflow::testing {
namespace {

constexpr uint32_t kTexelPx = SIVIFLOW_FLOW_TEXEL_PX;
constexpr uint32_t kTexelsWide = (kWidth + kTexelPx - 1) / kTexelPx;
constexpr double kPi = 3.14159265358979;

// The flow texel covering pixel (x, y) (shared.h layout).
gpu::FlowTexel texel_at(const Frame& frame, uint32_t x, uint32_t y) {
  gpu::FlowTexel texel;
  const size_t index = size_t{y / kTexelPx} * kTexelsWide + x / kTexelPx;
  std::memcpy(&texel, frame.flow_texture.data() + index * sizeof(texel), sizeof(texel));
  return texel;
}

// Hue in [0, 1) of an RGB colour, and its saturation (0 for grey).
double hue_of(const float* rgb, double* saturation) {
  const double hi = std::max({rgb[0], rgb[1], rgb[2]});
  const double lo = std::min({rgb[0], rgb[1], rgb[2]});
  *saturation = hi > 0.0 ? (hi - lo) / hi : 0.0;
  if (hi == lo) return 0.0;
  double h;
  if (hi == rgb[0]) {
    h = (rgb[1] - rgb[2]) / (hi - lo);
  } else if (hi == rgb[1]) {
    h = 2.0 + (rgb[2] - rgb[0]) / (hi - lo);
  } else {
    h = 4.0 + (rgb[0] - rgb[1]) / (hi - lo);
  }
  h /= 6.0;
  return h - std::floor(h);
}

// Angle between two hues, in degrees.
double hue_degrees(double a, double b) {
  const double d = std::fabs(a - b);
  return 360.0 * std::min(d, 1.0 - d);
}

class DebugViewTest : public RenderTest {
 protected:
  // Frames [0, 4) of the default scene through a fresh renderer showing `view`.
  Frame last_frame_with(DebugView view) {
    return fourth_frame_with([view](Renderer& renderer) { return renderer.set_debug_view(view); });
  }
};

TEST_F(DebugViewTest, FlowViewHueIsTheDirectionOfEachPixelsFlowTexel) {
  const Frame frame = last_frame_with(DebugView::kFlowDirection);
  ASSERT_FALSE(frame.rgba.empty());
  std::vector<double> errors;
  size_t arrow_pixels = 0;
  size_t water = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      if (frame.water_mask[size_t{y} * kWidth + x] != 1.0f) continue;
      ++water;
      const float* rgb = frame.pixel(x, y);
      if (std::min({rgb[0], rgb[1], rgb[2]}) > 0.9f) ++arrow_pixels;
      const gpu::FlowTexel texel = texel_at(frame, x, y);
      const double fx = glm::unpackHalf1x16(texel.flow_x);
      const double fz = glm::unpackHalf1x16(texel.flow_z);
      if (texel.id == SIVIFLOW_PARTICLE_NONE || std::hypot(fx, fz) < 0.05) continue;
      double saturation = 0.0;
      const double hue = hue_of(rgb, &saturation);
      if (saturation < 0.2) continue;  // an arrow's white core: no hue left to read
      double expected = std::atan2(fz, fx) / (2.0 * kPi);
      expected -= std::floor(expected);
      errors.push_back(hue_degrees(hue, expected));
    }
  }
  ASSERT_GT(water, 2000u);
  ASSERT_GT(errors.size(), water / 2) << "most water pixels should carry a flow's hue";
  std::sort(errors.begin(), errors.end());
  const double p95 = errors[errors.size() * 95 / 100];
  EXPECT_LT(p95, 3.0) << "95th percentile hue error in degrees";
  // One arrow per tile in view: some water is white, most is not.
  EXPECT_GT(arrow_pixels, water / 200);
  EXPECT_LT(arrow_pixels, water / 4);
}

TEST_F(DebugViewTest, ParticlesViewGivesEachParticleOneColourOfItsOwn) {
  const Frame frame = last_frame_with(DebugView::kParticles);
  ASSERT_FALSE(frame.rgba.empty());
  std::map<uint16_t, std::vector<float>> colour_of;
  size_t inconsistent = 0;
  size_t covered = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      if (frame.water_mask[size_t{y} * kWidth + x] != 1.0f) continue;
      const gpu::FlowTexel texel = texel_at(frame, x, y);
      const float* rgb = frame.pixel(x, y);
      if (texel.id == SIVIFLOW_PARTICLE_NONE) {
        EXPECT_EQ(rgb[0] + rgb[1] + rgb[2], 0.0f) << "no particle: black at " << x << "," << y;
        continue;
      }
      ++covered;
      auto [it, inserted] = colour_of.try_emplace(texel.id, std::vector<float>(rgb, rgb + 3));
      if (!inserted && !std::equal(rgb, rgb + 3, it->second.begin())) ++inconsistent;
    }
  }
  ASSERT_GT(covered, 2000u);
  EXPECT_EQ(inconsistent, 0u) << "a particle's pixels differ in colour";
  ASSERT_GT(colour_of.size(), 50u);
  // Colours tell particles apart: few pairs of particles share one.
  std::vector<std::vector<float>> colours;
  for (const auto& [id, colour] : colour_of) colours.push_back(colour);
  std::sort(colours.begin(), colours.end());
  const size_t distinct = std::unique(colours.begin(), colours.end()) - colours.begin();
  EXPECT_GT(distinct, colour_of.size() * 9 / 10);
}

TEST_F(DebugViewTest, TileGridOnlyDrawsLinesOverTheLookAndNoViewTouchesTheAovs) {
  const Frame look = last_frame_with(DebugView::kNone);
  const Frame grid = last_frame_with(DebugView::kTileGrid);
  ASSERT_FALSE(look.rgba.empty());
  ASSERT_FALSE(grid.rgba.empty());
  EXPECT_EQ(grid.normal, look.normal);
  EXPECT_EQ(grid.reflection, look.reflection);
  EXPECT_EQ(grid.water_mask, look.water_mask);
  size_t water = 0;
  size_t changed = 0;
  size_t changed_off_water = 0;
  for (size_t i = 0; i < look.water_mask.size(); ++i) {
    // A line: a clear step towards its yellow or cyan (the grid's edges fade out as a tile
    // shrinks to a few pixels, so faint changes are not counted).
    double step = 0.0;
    for (int c = 0; c < 4; ++c) {
      step = std::max(step, std::fabs(double{grid.rgba[i * 4 + c]} - look.rgba[i * 4 + c]));
    }
    const bool differs = step > 0.1;
    if (look.water_mask[i] == 1.0f) {
      ++water;
      changed += differs ? 1 : 0;
    } else {
      changed_off_water += differs ? 1 : 0;
    }
  }
  ASSERT_GT(water, 2000u);
  EXPECT_EQ(changed_off_water, 0u);
  std::printf("tile grid: %zu of %zu water pixels are lines\n", changed, water);
  EXPECT_GT(changed, water / 50) << "the grid's lines should show";
  EXPECT_LT(changed, water / 2) << "lines, not a fill";
  // Back to none: the look, bit for bit.
  const Frame again = last_frame_with(DebugView::kNone);
  EXPECT_EQ(again.rgba, look.rgba);
}

TEST_F(DebugViewTest, AViewOutsideTheEnumIsRefusedAndChangesNothing) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  ASSERT_TRUE(renderer_->set_debug_view(DebugView::kParticles).ok());
  const Status status = renderer_->set_debug_view(static_cast<DebugView>(kDebugViewCount));
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("set_debug_view: 4 is not a DebugView"), std::string::npos)
      << status.message();
  EXPECT_EQ(renderer_->debug_view(), DebugView::kParticles);
  EXPECT_STREQ(debug_view_name(DebugView::kTileGrid), "tiles");
  EXPECT_STREQ(debug_view_name(static_cast<DebugView>(9)), "");
}

}  // namespace
}  // namespace siviflow::testing
