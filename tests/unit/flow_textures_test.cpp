// Flow Texture Mapper: the staging layout, the nearest-particle texels, the aux texels addressed
// by id, and a round trip (unpacking the staging bytes gives back the ids and values).
#include "sim/flow_textures.h"

#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "unit/particle_scenes.h"

namespace siviflow {
namespace {

Particle make_particle(uint32_t id, uint16_t slot, glm::vec2 screen, glm::vec3 flow, float speed,
                       float depth, float foam, float fade, ParticleState state) {
  Particle p;
  p.id = id;
  p.slot = slot;
  p.screen = screen;
  p.flow = flow;
  p.speed = speed;
  p.depth = depth;
  p.foam = foam;
  p.fade = fade;
  p.state = state;
  return p;
}

TEST(FlowTextures, LayoutOfTheStagingBlock) {
  FlowTextureLayout l;
  ASSERT_TRUE(make_flow_texture_layout({1280, 720}, 4, 3000, &l).ok());
  EXPECT_EQ(l.flow_extent, glm::uvec2(320, 180));
  EXPECT_EQ(l.flow_offset, 0u);
  EXPECT_EQ(l.flow_bytes, 320u * 180u * 8u);
  EXPECT_EQ(l.aux_offset % kStagingBlockAlignment, 0u);
  EXPECT_GE(l.aux_offset, l.flow_bytes);
  EXPECT_EQ(l.aux_extent, glm::uvec2(256, 12));  // ids 0..3000 need 3001 texels
  EXPECT_EQ(l.aux_bytes, 256u * 12u * 16u);
  EXPECT_EQ(l.total_bytes, l.aux_offset + l.aux_bytes);
  // Sizes that do not divide: the last texel column covers the remaining pixels.
  ASSERT_TRUE(make_flow_texture_layout({1918, 1081}, 4, 1, &l).ok());
  EXPECT_EQ(l.flow_extent, glm::uvec2(480, 271));
  EXPECT_EQ(l.aux_extent, glm::uvec2(256, 1));
  EXPECT_FALSE(make_flow_texture_layout({1280, 720}, 0, 10, &l).ok());
  EXPECT_FALSE(make_flow_texture_layout({0, 720}, 4, 10, &l).ok());
  EXPECT_FALSE(make_flow_texture_layout({1280, 720}, 4, 70000, &l).ok());
  EXPECT_FALSE(make_flow_texture_layout({1280, 720}, 4, 0, &l).ok());
}

TEST(FlowTextures, EachTexelTakesTheNearestParticleWithinTheCoverRadius) {
  FlowTextureLayout l;
  ASSERT_TRUE(make_flow_texture_layout({64, 32}, 4, 10, &l).ok());
  FlowTextures t;
  ASSERT_TRUE(FlowTextures::create(l, &t).ok());
  const std::vector<Particle> ps = {
      make_particle(5, 3, {10.0f, 10.0f}, {1, 0, 0}, 1.5f, 2.0f, 0.01f, 1.0f, ParticleState::kActive),
      make_particle(9, 7, {30.0f, 10.0f}, {0, 0, -2}, 0.5f, 1.0f, 0.02f, 0.3f, ParticleState::kFadingOut),
  };
  std::vector<std::byte> staging(l.total_bytes, std::byte{0xab});
  ASSERT_TRUE(t.pack(ps, 12.0f, staging).ok());
  gpu::FlowTexel texel;
  // Texel (2, 2) has its centre at (10, 10): particle slot 3.
  ASSERT_TRUE(read_flow_texel(staging, l, 2, 2, &texel).ok());
  EXPECT_EQ(texel.id, 3);
  EXPECT_EQ(decode_flow(texel), glm::vec3(1, 0, 0));
  // Texel (7, 2), centre (30, 10): the fading-out particle still owns its texels.
  ASSERT_TRUE(read_flow_texel(staging, l, 7, 2, &texel).ok());
  EXPECT_EQ(texel.id, 7);
  EXPECT_EQ(decode_flow(texel), glm::vec3(0, 0, -2));
  // Texel (4, 2), centre (18, 10): 8 px from the first, 12 from the second.
  ASSERT_TRUE(read_flow_texel(staging, l, 4, 2, &texel).ok());
  EXPECT_EQ(texel.id, 3);
  // Texel (15, 7), centre (62, 30): beyond both cover radii.
  ASSERT_TRUE(read_flow_texel(staging, l, 15, 7, &texel).ok());
  EXPECT_EQ(texel.id, SIVIFLOW_PARTICLE_NONE);
  EXPECT_EQ(texel.flow_x | texel.flow_y | texel.flow_z, 0);
  gpu::ParticleAux aux;
  ASSERT_TRUE(read_particle_aux(staging, l, 7, &aux).ok());
  EXPECT_EQ(aux.speed, 0.5f);
  EXPECT_EQ(aux.depth, 1.0f);
  EXPECT_EQ(aux.foam, 0.02f);
  EXPECT_EQ(aux.fade, 0.3f);
  for (uint32_t id : {0u, 1u, 4u, 10u}) {
    ASSERT_TRUE(read_particle_aux(staging, l, id, &aux).ok());
    EXPECT_EQ(aux.speed + aux.depth + aux.foam + aux.fade, 0.0f) << "id " << id;
  }
  // Every byte of the block is written (padding included).
  for (size_t i = l.flow_bytes; i < l.aux_offset; ++i) ASSERT_EQ(staging[i], std::byte{0});
  EXPECT_FALSE(read_flow_texel(staging, l, 16, 0, &texel).ok());
  EXPECT_FALSE(read_particle_aux(staging, l, 11, &aux).ok());
}

TEST(FlowTextures, RejectsBadInput) {
  FlowTextureLayout l;
  ASSERT_TRUE(make_flow_texture_layout({64, 32}, 4, 10, &l).ok());
  FlowTextures t;
  ASSERT_TRUE(FlowTextures::create(l, &t).ok());
  std::vector<std::byte> staging(l.total_bytes);
  const Particle ok = make_particle(1, 1, {5, 5}, {1, 0, 0}, 1, 1, 0, 1, ParticleState::kActive);
  std::vector<std::byte> small(l.total_bytes - 1);
  EXPECT_FALSE(t.pack(std::span(&ok, 1), 8.0f, small).ok());
  std::vector<Particle> dup = {ok, ok};
  dup[1].id = 2;
  EXPECT_FALSE(t.pack(dup, 8.0f, staging).ok());
  Particle bad = ok;
  bad.slot = 11;
  EXPECT_FALSE(t.pack(std::span(&bad, 1), 8.0f, staging).ok());
  bad.slot = 0;
  EXPECT_FALSE(t.pack(std::span(&bad, 1), 8.0f, staging).ok());
  bad = ok;
  bad.screen.x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_FALSE(t.pack(std::span(&bad, 1), 8.0f, staging).ok());
  EXPECT_FALSE(t.pack(std::span(&ok, 1), -1.0f, staging).ok());
  FlowTextureLayout forged = l;
  forged.total_bytes = 16;
  EXPECT_FALSE(FlowTextures::create(forged, &t).ok());
}

TEST(FlowTextures, PackingRoundTripsAFieldsParticles) {
  const test::GridRiver r = test::straight_channel(40.0f, 300.0f, 21, 151, 1.0f, 0.3f);
  ParticleParams params;
  params.viewport = {640, 360};
  params.seed = 5;
  ParticleField field;
  ASSERT_TRUE(ParticleField::create(r.field(), params, &field).ok());
  FlowTextures t;
  ASSERT_TRUE(FlowTextures::create(field, 4, &t).ok());
  const FlowTextureLayout& l = t.layout();
  std::vector<std::byte> staging(l.total_bytes);
  size_t owned_checked = 0;
  for (uint64_t f = 0; f < 12; ++f) {
    const glm::vec3 eye(0.0f, 10.0f, -5.0f + 1.5f * f);
    ASSERT_TRUE(field.update(test::look_at(eye, eye + glm::vec3(0.2f, -0.4f, 1.0f), params.viewport),
                             f, 1.0f / 30.0f).ok());
    if (f % 4 != 3) continue;  // pack a few of the frames: the oracle below is brute force
    ASSERT_TRUE(t.pack(field, staging).ok());
    const auto ps = field.particles();
    std::map<uint16_t, const Particle*> by_slot;
    for (const Particle& p : ps) by_slot[p.slot] = &p;
    const float radius = kFlowCoverRadiusFactor * field.cover_radius_px();
    for (uint32_t y = 0; y < l.flow_extent.y; ++y) {
      for (uint32_t x = 0; x < l.flow_extent.x; ++x) {
        gpu::FlowTexel texel;
        ASSERT_TRUE(read_flow_texel(staging, l, x, y, &texel).ok());
        const glm::vec2 centre((x + 0.5f) * l.texel_px, (y + 0.5f) * l.texel_px);
        float nearest = std::numeric_limits<float>::infinity();
        for (const Particle& p : ps) nearest = std::min(nearest, glm::length(p.screen - centre));
        if (texel.id == SIVIFLOW_PARTICLE_NONE) {
          ASSERT_GE(nearest, radius * (1.0f - 1e-4f)) << "texel " << x << ", " << y;
          continue;
        }
        ASSERT_TRUE(by_slot.count(texel.id)) << "texel " << x << ", " << y << " id " << texel.id;
        const Particle& p = *by_slot[texel.id];
        ASSERT_NEAR(glm::length(p.screen - centre), nearest, 1e-3f) << "not the nearest particle";
        EXPECT_EQ(texel.flow_x, to_half(p.flow.x));
        EXPECT_EQ(texel.flow_y, to_half(p.flow.y));
        EXPECT_EQ(texel.flow_z, to_half(p.flow.z));
        EXPECT_NEAR(decode_flow(texel).z, p.flow.z, 1e-3f);
        ++owned_checked;
      }
    }
    for (uint32_t id = 0; id <= l.slot_count; ++id) {
      gpu::ParticleAux aux;
      ASSERT_TRUE(read_particle_aux(staging, l, id, &aux).ok());
      const auto it = by_slot.find(static_cast<uint16_t>(id));
      if (it == by_slot.end()) {
        ASSERT_EQ(aux.speed + aux.depth + aux.foam + aux.fade, 0.0f) << "unused id " << id;
        continue;
      }
      EXPECT_EQ(aux.speed, it->second->speed);
      EXPECT_EQ(aux.depth, it->second->depth);
      EXPECT_EQ(aux.foam, it->second->foam);
      EXPECT_EQ(aux.fade, it->second->fade);
    }
  }
  EXPECT_GT(owned_checked, 5000u);
}

}  // namespace
}  // namespace siviflow
