// The water draws its foam where the flow made it: the pixels that foam whitens are those whose
// particles carry foam (sim/foam.h, through the aux texture and the tile table), open water stays
// clear, and foam_amount 0 draws none; behind a boulder the foam AOV shows its wake, which
// follows the boulder in the very next frame when it moves.
#include <cstdio>
#include <cstring>
#include <vector>

#include <gtest/gtest.h>

#include "render_frames.h"
#include "straight_channel.h"
#include "shaders/shared.h"
#include "renderer_inspect.h"
#include "sim/flow_textures.h"

namespace siviflow::testing {
namespace {

class FoamRenderTest : public RenderTest {
 protected:
  // Frame 3 of the default scene with the default look but `foam_amount`.
  Frame frame_with_foam(float foam_amount) {
    WaterLook look;
    look.foam_amount = foam_amount;
    return fourth_frame_with([&look](Renderer& renderer) { return renderer.set_look(look); });
  }
};

double luminance(const float* rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

TEST_F(FoamRenderTest, FoamWhitensTheWaterWhoseParticlesCarryFoam) {
  const Frame clear = frame_with_foam(0.0f);
  const Frame foamy = frame_with_foam(1.0f);
  ASSERT_FALSE(clear.rgba.empty());
  ASSERT_FALSE(foamy.rgba.empty());
  EXPECT_EQ(clear.flow_texture, foamy.flow_texture) << "the look does not move the particles";
  const FlowTextureLayout& layout = flow_texture_layout(*renderer_);
  std::vector<std::byte> staging(layout.total_bytes);
  std::memcpy(staging.data() + layout.flow_offset, foamy.flow_texture.data(), layout.flow_bytes);
  std::memcpy(staging.data() + layout.aux_offset, foamy.particle_aux.data(), layout.aux_bytes);
  // Foam shows as patches where the ripples rise above 1 - foam: the more foam a particle
  // carries, the more of its pixels are white; none where it carries none.
  size_t whitened[2] = {}, pixels[2] = {};  // [0] particles with no foam, [1] with foam > 0.5
  size_t water = 0, darkened = 0, whitened_all = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      if (foamy.water_mask[size_t{y} * kWidth + x] != 1.0f) continue;
      ++water;
      gpu::FlowTexel texel{};
      ASSERT_TRUE(read_flow_texel(staging, layout, x / layout.texel_px, y / layout.texel_px,
                                  &texel).ok());
      if (texel.id == SIVIFLOW_PARTICLE_NONE) continue;
      gpu::ParticleAux aux{};
      ASSERT_TRUE(read_particle_aux(staging, layout, texel.id, &aux).ok());
      const double change = luminance(foamy.pixel(x, y)) - luminance(clear.pixel(x, y));
      whitened_all += change > 0.05 ? 1 : 0;
      darkened += change < -0.05 ? 1 : 0;  // foam hides a glint
      const int bin = aux.foam < 0.02f ? 0 : aux.foam > 0.5f ? 1 : -1;
      if (bin < 0) continue;
      ++pixels[bin];
      whitened[bin] += change > 0.05 ? 1 : 0;
    }
  }
  ASSERT_GT(water, 2000u);
  ASSERT_GT(pixels[0], water / 10);
  ASSERT_GT(pixels[1], water / 100);
  const double share[2] = {double(whitened[0]) / pixels[0], double(whitened[1]) / pixels[1]};
  std::printf("foam: %zu of %zu water pixels whitened, %zu darker; whitened share where the "
              "particle has no foam %.3f (%zu px), foam > 0.5 %.3f (%zu px)\n", whitened_all,
              water, darkened, share[0], pixels[0], share[1], pixels[1]);
  EXPECT_GT(whitened_all, water / 100) << "foam shows";
  EXPECT_LT(whitened_all, water / 2) << "most of the river is open water";
  // Foam from a neighbouring tile may reach into a clear particle's pixels (tiles blend), and a
  // streak of foam narrower than a tile (3 m) is thinned by its clear neighbours: foamy
  // particles' pixels whiten far more often than clear ones', not always.
  EXPECT_LT(share[0], 0.05) << "open water stays clear";
  EXPECT_GT(share[1], 0.06) << "foamy water shows foam";
  EXPECT_GT(share[1], 5.0 * share[0]);
  EXPECT_LT(darkened, water / 50);
}

class FoamWakeTest : public StraightChannelTest {
 protected:
  struct Wake {
    double downstream = 0.0;  // mean foam.Y within four radii downstream of the boulder
    double upstream = 0.0;    // and the same upstream
    double foamy_share = 0.0; // of the water with foam.Y above 0.1
  };

  // The water pixels within four radii of the boulder's edge at `centre`, more than a radius
  // downstream (or upstream) of its centre and within two radii of its line.
  Wake wake(const Frame& frame, const glm::vec3& centre) const {
    double sum[2] = {}, count[2] = {};
    size_t water = 0, foamy = 0;
    for (uint32_t y = 0; y < kHeight; ++y) {
      for (uint32_t x = 0; x < kWidth; ++x) {
        const size_t i = size_t{y} * kWidth + x;
        if (frame.water_mask[i] != 1.0f) continue;
        ++water;
        foamy += frame.foam[i] > 0.1f ? 1 : 0;
        const glm::vec2 offset = water_point(x, y) - glm::vec2(centre.x, centre.z);
        if (std::abs(offset.x) > 2.0f * kBoulderRadius || std::abs(offset.y) < kBoulderRadius ||
            std::abs(offset.y) > 5.0f * kBoulderRadius) {
          continue;
        }
        const int side = offset.y > 0.0f ? 0 : 1;  // the river flows along +Z
        sum[side] += frame.foam[i];
        count[side] += 1.0;
      }
    }
    EXPECT_GT(count[0], 300.0);
    EXPECT_GT(count[1], 300.0);
    return {sum[0] / std::max(count[0], 1.0), sum[1] / std::max(count[1], 1.0),
            double(foamy) / std::max<size_t>(water, 1)};
  }
};

TEST_F(FoamWakeTest, FoamTrailsTheBoulderAndFollowsItWhenItMoves) {
  const glm::vec3 left{-2.8f, 0.0f, 0.0f}, right{2.8f, 0.0f, 0.0f};
  Status status = create_channel(make_create_info(kWidth, kHeight), left);
  ASSERT_TRUE(status.ok()) << status.message();
  const std::vector<Frame> before = render_still(0, 3);
  ASSERT_TRUE(move_boulder(right).ok());
  const std::vector<Frame> after = render_still(3, 4);
  ASSERT_EQ(before.size(), 3u);
  ASSERT_EQ(after.size(), 1u);
  const Wake still = wake(before.back(), left);
  const Wake moved = wake(after[0], right);
  const Wake left_behind = wake(after[0], left);
  std::printf("foam.Y behind the boulder %.3f, before it %.3f (ratio %.1f), foamy water %.2f; "
              "moved: behind its new place %.3f, before it %.3f, behind its old place %.3f\n",
              still.downstream, still.upstream, still.downstream / std::max(still.upstream, 1e-6),
              still.foamy_share, moved.downstream, moved.upstream, left_behind.downstream);
  EXPECT_GT(still.downstream, 0.05) << "the boulder has a wake";
  EXPECT_GE(still.downstream, 3.0 * still.upstream) << "the wake lies downstream";
  EXPECT_LT(still.foamy_share, 1.0 / 3.0) << "most of the river is open water";
  EXPECT_GE(moved.downstream, 3.0 * moved.upstream) << "the next frame's wake trails the new place";
  EXPECT_GE(moved.downstream, 3.0 * left_behind.downstream) << "and has left the old one";
}

}  // namespace
}  // namespace siviflow::testing
