// The default scene through the embedding path: validation-clean, plausible pixels,
// deterministic, and host image states honoured.
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <vector>

#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include "render_frames.h"
#include "scene/default_scene.h"
#include "renderer_inspect.h"
#include "siviflow/host_frame.h"
#include "shaders/shared.h"
#include "sim/flow_textures.h"
#include "view_proj.h"

namespace siviflow::testing {
namespace {

TEST_F(RenderTest, DeviceIsLavapipeWithValidation) {
  EXPECT_TRUE(context_->report().validation_enabled);
  if (std::getenv("SIVIFLOW_EXPECT_LAVAPIPE") != nullptr) {
    EXPECT_EQ(context_->report().driver_id, VK_DRIVER_ID_MESA_LLVMPIPE) << context_->report().device_name;
    EXPECT_NE(context_->report().device_name.find("llvmpipe"), std::string::npos);
  }
}

TEST_F(RenderTest, DefaultSceneShowsSkyAboveTerrainBelow) {
  const std::vector<Frame> frames = render(0, 1);
  ASSERT_EQ(frames.size(), 1u);
  const Frame& f = frames[0];
  // Sky at the top centre: blue dominates, moderately bright, nothing drawn there (far depth).
  const float* sky = f.pixel(kWidth / 2, 4);
  EXPECT_GT(sky[2], sky[0]);
  EXPECT_GT(sky[2], 0.5f);
  EXPECT_LT(sky[2], 1.5f);
  EXPECT_EQ(f.depth[4 * kWidth + kWidth / 2], 1.0f);
  // Terrain at the bottom centre: the (dry) riverbed, warmer than the sky and near the camera.
  const float* ground = f.pixel(kWidth / 2, kHeight - 4);
  EXPECT_GE(ground[0], ground[2]);
  EXPECT_GT(ground[0] + ground[1] + ground[2], 0.05f);
  EXPECT_LT(ground[0] + ground[1] + ground[2], 3.0f);
  EXPECT_LT(f.depth[(kHeight - 4) * kWidth + kWidth / 2], 0.999f);
  // Opaque everywhere, and the frame is not constant.
  double sum = 0.0;
  double sum_sq = 0.0;
  for (size_t i = 0; i < size_t{kWidth} * kHeight; ++i) {
    EXPECT_EQ(f.rgba[i * 4 + 3], 1.0f) << "pixel " << i;
    const double luma = f.rgba[i * 4] + f.rgba[i * 4 + 1] + f.rgba[i * 4 + 2];
    sum += luma;
    sum_sq += luma * luma;
    if (HasFailure()) break;
  }
  const double n = double{kWidth} * kHeight;
  EXPECT_GT(sum_sq / n - (sum / n) * (sum / n), 0.01) << "the frame is (nearly) constant";
}

TEST_F(RenderTest, WaterMaskCoversTheRiverOnly) {
  const std::vector<Frame> frames = render(0, 1);
  ASSERT_EQ(frames.size(), 1u);
  const Frame& f = frames[0];
  size_t water = 0;
  for (size_t i = 0; i < f.water_mask.size(); ++i) {
    ASSERT_TRUE(f.water_mask[i] == 0.0f || f.water_mask[i] == 1.0f) << "pixel " << i;
    if (f.water_mask[i] == 1.0f) {
      ++water;
      EXPECT_LT(f.depth[i], 1.0f) << "water seen where only sky is: pixel " << i;
    }
  }
  // The camera looks down the river: water below the centre, none in the sky at the top.
  EXPECT_EQ(f.water_mask[4 * kWidth + kWidth / 2], 0.0f);
  EXPECT_EQ(f.water_mask[(kHeight - 4) * kWidth + kWidth / 2], 1.0f);
  EXPECT_GT(water, size_t{kWidth} * kHeight / 20);
  EXPECT_LT(water, size_t{kWidth} * kHeight / 2);
}

// The mean tilt of the water's normals in each frame (all unit, pointing up).
std::vector<double> mean_tilts(const std::vector<Frame>& frames) {
  std::vector<double> means;
  for (const Frame& f : frames) {
    double tilt = 0.0;
    size_t water = 0;
    for (size_t i = 0; i < f.water_mask.size(); ++i) {
      if (f.water_mask[i] != 1.0f) continue;
      const float* n = &f.normal[i * 4];
      EXPECT_NEAR(std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), 1.0, 1e-3) << "pixel " << i;
      EXPECT_GT(n[1], 0.0f) << "the water normal points up";
      tilt += std::sqrt(n[0] * n[0] + n[2] * n[2]);
      ++water;
    }
    EXPECT_GT(water, 100u);
    means.push_back(tilt / static_cast<double>(std::max<size_t>(water, 1)));
  }
  return means;
}

TEST_F(RenderTest, WaterNormalIsUnitAndItsTiltDoesNotPulse) {
  // Over frames 15..59 (the particles have faded in), (max - min) / max of the mean tilt:
  // steady with Tiled Directional Flow; the two-phase flow map's dips at each cross-fade, once
  // a cycle, the pulsing it is known for (shown for contrast).
  const auto variation = [this](WaterMaterial material) {
    renderer_.reset();
    std::vector<Frame> frames = render(0, 1, 160, 90);  // creates the renderer
    WaterLook look;
    look.material = material;
    EXPECT_TRUE(renderer_->set_look(look).ok());
    const std::vector<Frame> rest = render(1, 60, 160, 90);
    frames.insert(frames.end(), rest.begin(), rest.end());
    EXPECT_EQ(frames.size(), 60u);
    const std::vector<double> means = mean_tilts(frames);
    const auto [lo, hi] = std::minmax_element(means.begin() + 15, means.end());
    EXPECT_GT(*lo, 0.01) << "the water shows ripples";
    return (*hi - *lo) / *hi;
  };
  const double tiled = variation(WaterMaterial::kTiledDirectionalFlow);
  const double flow_map = variation(WaterMaterial::kFlowMap);
  std::printf("mean tilt varies by %.1f %% with Tiled Directional Flow, %.1f %% with the flow map\n",
              100.0 * tiled, 100.0 * flow_map);
  EXPECT_LT(tiled, 0.15) << "no pulsing";
  EXPECT_GT(flow_map, 2.0 * tiled) << "the baseline pulses";
}

TEST_F(RenderTest, MovingObstacleReroutesTheParticlesFlow) {
  const ProceduralRiver river(default_river_params());
  const Obstacle moving = default_scene_obstacles(river).back();
  const glm::vec3 in_water = moving.keys.back().centre;  // where it ends, in the river
  RiverMesh mesh;
  ASSERT_TRUE(river.generate_mesh(&mesh).ok());
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  // A camera above the spot, so that particles are dense there (a few per metre).
  Camera above;
  above.position = in_water + glm::vec3(0.0f, 6.0f, -4.0f);
  above.target = in_water;
  // The mean flow of particles whose river vertex lies where the boulder ends up, at frame `last`.
  const auto flow_at_destination = [&](uint32_t last, size_t* count) {
    while (renderer_->next_frame() <= last) {
      const double t = static_cast<double>(renderer_->next_frame()) / 30.0;
      EXPECT_TRUE(renderer_->simulate(camera_view(above, {kWidth, kHeight}), t).ok());
    }
    double speed = 0.0;
    *count = 0;
    for (const Particle& p : particle_field(*renderer_).particles()) {
      const glm::vec3& v = mesh.positions[p.vertex];
      if (glm::length(glm::vec2(v.x - in_water.x, v.z - in_water.z)) > 0.9f * moving.radius) continue;
      speed += glm::length(p.flow);
      ++*count;
    }
    return *count == 0 ? 0.0 : speed / static_cast<double>(*count);
  };
  size_t before_count = 0;
  const double before = flow_at_destination(15, &before_count);  // t = 0.5 s: still on the bank
  size_t after_count = 0;
  const double after = flow_at_destination(135, &after_count);   // t = 4.5 s: in the river
  ASSERT_GT(before_count, 0u) << "the camera sees the water there";
  EXPECT_GT(before, 0.3) << "open water flows";
  ASSERT_GT(after_count, 0u);
  EXPECT_EQ(after, 0.0) << "inside the obstacle the water is dry: velocity 0";
}

struct HostReflectionLog {
  int calls = 0;
  ReflectionView last{};
};

void record_nothing(VkCommandBuffer, const ReflectionView& view, void* user) {
  auto* log = static_cast<HostReflectionLog*>(user);
  ++log->calls;
  log->last = view;
}

TEST_F(RenderTest, HostCanReplaceWhatTheWaterReflects) {
  // Our own reflection: the sky and the banks show in the water.
  const std::vector<Frame> ours = render(0, 1);
  ASSERT_EQ(ours.size(), 1u);
  ASSERT_TRUE(context_->wait_idle().ok());
  renderer_.reset();
  // A host that draws nothing into the reflection: the water reflects the sky.
  HostReflectionLog log;
  CreateInfo info = make_create_info(kWidth, kHeight);
  info.reflection = &record_nothing;
  info.reflection_user = &log;
  ASSERT_TRUE(create_renderer(info).ok());
  const std::vector<Frame> host = render(0, 1);
  ASSERT_EQ(host.size(), 1u);
  EXPECT_EQ(log.calls, 1);
  EXPECT_EQ(log.last.extent.width, kWidth / 2);
  EXPECT_EQ(log.last.extent.height, kHeight / 2);
  EXPECT_FLOAT_EQ(log.last.clip_plane[1], 1.0f) << "keeps what is above the water";
  EXPECT_LT(log.last.camera_position[1], 0.0f) << "the mirrored camera is below the water";
  size_t water = 0;
  size_t same = 0;
  for (size_t i = 0; i < host.front().water_mask.size(); ++i) {
    if (host.front().water_mask[i] != 1.0f) continue;
    ++water;
    const float* reflected = &host.front().reflection[i * 4];
    EXPECT_GT(reflected[2], reflected[0]) << "the sky along the reflected ray, blue; pixel " << i;
    if (std::memcmp(&ours.front().reflection[i * 4], reflected, 3 * sizeof(float)) == 0) ++same;
    if (HasFailure()) break;
  }
  EXPECT_GT(water, 100u);
  EXPECT_LT(same, water / 10) << "our world's reflection differs from the sky alone";
}

TEST_F(RenderTest, UploadedFlowTexturesEqualThePackedBytes) {
  // Two frames: the second reuses the images and the other staging slot.
  const std::vector<Frame> frames = render(0, 2);
  ASSERT_EQ(frames.size(), 2u);
  const ParticleField& field = particle_field(*renderer_);
  ASSERT_FALSE(field.particles().empty());
  FlowTextures textures;
  ASSERT_TRUE(FlowTextures::create(field, kDefaultFlowTexelPx, &textures).ok());
  const FlowTextureLayout& layout = textures.layout();
  std::vector<std::byte> packed(layout.total_bytes);
  ASSERT_TRUE(textures.pack(field, packed).ok());
  const Frame& last = frames[1];
  ASSERT_EQ(last.flow_texture.size(), layout.flow_bytes);
  ASSERT_EQ(last.particle_aux.size(), layout.aux_bytes);
  EXPECT_EQ(std::memcmp(last.flow_texture.data(), packed.data() + layout.flow_offset, layout.flow_bytes), 0);
  EXPECT_EQ(std::memcmp(last.particle_aux.data(), packed.data() + layout.aux_offset, layout.aux_bytes), 0);
  // And the values decode to the particles': aux by slot, and a particle's own texel names it
  // (unless a neighbour sits nearer to that texel's centre, which the spacing makes rare).
  std::vector<std::byte> read_back(layout.total_bytes);
  std::memcpy(read_back.data() + layout.flow_offset, last.flow_texture.data(), layout.flow_bytes);
  std::memcpy(read_back.data() + layout.aux_offset, last.particle_aux.data(), layout.aux_bytes);
  size_t on_screen = 0;
  size_t own_texel = 0;
  for (const Particle& p : field.particles()) {
    gpu::ParticleAux aux{};
    ASSERT_TRUE(read_particle_aux(read_back, layout, p.slot, &aux).ok());
    EXPECT_FLOAT_EQ(aux.speed, p.speed);
    EXPECT_FLOAT_EQ(aux.depth, p.depth);
    EXPECT_FLOAT_EQ(aux.foam, p.foam);
    EXPECT_FLOAT_EQ(aux.fade, p.fade);
    if (p.screen.x < 0 || p.screen.y < 0 || p.screen.x >= kWidth || p.screen.y >= kHeight) continue;
    ++on_screen;
    gpu::FlowTexel texel{};
    ASSERT_TRUE(read_flow_texel(read_back, layout, static_cast<uint32_t>(p.screen.x) / layout.texel_px,
                                static_cast<uint32_t>(p.screen.y) / layout.texel_px, &texel).ok());
    if (texel.id == p.slot) {
      ++own_texel;
      const glm::vec3 flow = decode_flow(texel);
      EXPECT_NEAR(flow.x, p.flow.x, 2e-3f * (1.0f + std::abs(p.flow.x)));  // binary16
      EXPECT_NEAR(flow.z, p.flow.z, 2e-3f * (1.0f + std::abs(p.flow.z)));
    }
  }
  EXPECT_GT(on_screen, 20u);
  EXPECT_GE(own_texel * 100, on_screen * 95);
}

// Each tile of the water's Tiled Directional Flow takes the flow and foam of the particle under
// its centre: the tile table turns the map along that flow and scales it with its speed, and
// carries the foam to 1/255 and the roughness's turn-back factor for that speed. Checked where that particle lies within a tile of the centre: tiles farther from
// water are no water pixel's.
TEST_F(RenderTest, TileTableCarriesTheFlowUnderEachTileCentre) {
  const std::vector<Frame> frames = render(0, 2);
  ASSERT_EQ(frames.size(), 2u);
  const Frame& frame = frames[1];
  const TileTableLayout& table = renderer_->tile_table_layout();
  ASSERT_EQ(frame.tile_table.size(), size_t{table.width} * table.height * 4);
  const FlowTextureLayout& layout = flow_texture_layout(*renderer_);
  std::vector<std::byte> staging(layout.total_bytes);
  std::memcpy(staging.data() + layout.flow_offset, frame.flow_texture.data(), layout.flow_bytes);
  std::memcpy(staging.data() + layout.aux_offset, frame.particle_aux.data(), layout.aux_bytes);
  const glm::mat4 view_proj = view_proj_of(world_->scene_camera(1.0 / 30.0), kWidth, kHeight);
  const float water_level = particle_field(*renderer_).particles().front().world.y;  // level river
  const glm::vec2 texels = glm::vec2(kWidth, kHeight) / float(layout.texel_px);
  const glm::ivec2 size(table.width, table.height);
  const glm::ivec2 corner(table.corner_x, table.corner_z);
  std::vector<glm::vec3> particle_at(UINT16_MAX + 1);  // by slot
  for (const Particle& p : particle_field(*renderer_).particles()) particle_at[p.slot] = p.world;
  size_t checked = 0;
  size_t agreeing = 0;
  size_t foamy = 0;
  for (int y = 0; y < size.y; ++y) {
    for (int x = 0; x < size.x; ++x) {
      const glm::ivec2 lattice = corner + ((glm::ivec2(x, y) - corner) & (size - 1));
      const glm::vec2 centre = glm::vec2(lattice) * (0.5f * table.tile_size_m);
      const glm::vec4 clip = view_proj * glm::vec4(centre.x, water_level, centre.y, 1.0f);
      if (clip.w < 1e-3f) continue;
      const glm::vec2 at = (glm::vec2(clip) / clip.w * 0.5f + 0.5f) * texels;
      const glm::vec2 within = glm::fract(at);
      // Off screen, or so near a texel edge that GPU rounding may pick the neighbour: skipped.
      if (at.x < 0.0f || at.y < 0.0f || at.x >= texels.x || at.y >= texels.y ||
          glm::any(glm::lessThan(within, glm::vec2(0.02f))) ||
          glm::any(glm::greaterThan(within, glm::vec2(0.98f)))) {
        continue;
      }
      gpu::FlowTexel texel{};
      ASSERT_TRUE(read_flow_texel(staging, layout, uint32_t(at.x), uint32_t(at.y), &texel).ok());
      const glm::vec3 flow = decode_flow(texel);
      const float speed = glm::length(glm::vec2(flow.x, flow.z));
      if (texel.id == SIVIFLOW_PARTICLE_NONE || speed < 0.05f) continue;  // no direction to check
      const glm::vec3 particle = particle_at[texel.id];
      if (glm::distance(glm::vec2(particle.x, particle.z), centre) > table.tile_size_m) continue;
      ++checked;
      const uint32_t* tile = &frame.tile_table[(size_t(y) * size.x + x) * 4];
      glm::vec2 ab;
      std::memcpy(&ab, tile, sizeof(ab));
      // Map repeats per tile: 1 / 3.5 in still water, 1.5 / 3.5 from 1.5 m/s.
      const float scale = glm::mix(1.0f, 1.5f, std::clamp(speed / 1.5f, 0.0f, 1.0f)) / 3.5f;
      const float cos_angle = glm::dot(ab, glm::vec2(flow.x, flow.z)) / (glm::length(ab) * speed);
      gpu::ParticleAux aux{};
      ASSERT_TRUE(read_particle_aux(staging, layout, texel.id, &aux).ok());
      const float foam = static_cast<float>(tile[2] >> 24) / 255.0f;
      if (foam > 0.0f) ++foamy;
      // Roughness 0.4 in still water to 1 from 1.5 m/s, over the map repeats per tile.
      const float roughness = glm::mix(0.4f, 1.0f, std::clamp(speed / 1.5f, 0.0f, 1.0f));
      float back = 0.0f;
      std::memcpy(&back, &tile[3], sizeof(back));
      if (cos_angle > std::cos(glm::radians(0.5f)) && std::abs(glm::length(ab) - scale) < 1e-4f &&
          std::abs(foam - aux.foam) <= 0.5f / 255.0f + 1e-6f &&
          std::abs(back - roughness / scale) <= 1e-5f * back) {
        ++agreeing;
      } else {
        ADD_FAILURE() << "lattice point (" << lattice.x << ", " << lattice.y << "): flow ("
                      << flow.x << ", " << flow.z << "), table (" << ab.x << ", " << ab.y
                      << "), foam " << foam << " against the particle's " << aux.foam
                      << ", turn-back " << back << " against " << roughness / scale;
      }
    }
  }
  EXPECT_GT(checked, 100u);
  EXPECT_EQ(agreeing, checked);
  EXPECT_GT(foamy, 0u) << "some tiles near the banks carry foam";
}

// On a river longer than the tile table reaches (1.6 km against 768 m), the table's window lies
// ahead of the camera: every tile of every water pixel within its reach is one the table holds
// (water farther away, where a tile is a pixel or two, takes the tiles a table size nearer).
TEST_F(RenderTest, TileTableWindowHoldsEveryTileInViewOfALongRiver) {
  SceneFile scene;
  const Status parsed = parse_scene_file(
      R"({"version":1,"river":{"procedural":{"length":1600,"meander_amplitude":1}},)"
      R"("camera":{"keys":[{"t":0,"position":[0,6,-400],"target":[0,0,-305]}]}})",
      "long.json", ".", &scene);
  ASSERT_TRUE(parsed.ok()) << parsed.message();
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight), &scene).ok());
  const std::vector<Frame> frames = render(0, 1);
  ASSERT_EQ(frames.size(), 1u);
  const Frame& frame = frames[0];
  const TileTableLayout& table = renderer_->tile_table_layout();
  ASSERT_EQ(table.height, SIVIFLOW_TILE_TABLE_MAX);  // the river (along z) does not fit: a window
  const glm::mat4 to_world = glm::inverse(view_proj_of(world_->scene_camera(0.0), kWidth, kHeight));
  const glm::ivec2 lo(table.corner_x, table.corner_z);
  const glm::ivec2 hi = lo + glm::ivec2(table.width, table.height) - 1;
  size_t water = 0;
  float farthest = 0.0f;
  size_t outside = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 0; x < kWidth; ++x) {
      const size_t i = size_t{y} * kWidth + x;
      if (frame.water_mask[i] != 1.0f) continue;
      ++water;
      const glm::vec4 ndc(2.0f * (x + 0.5f) / kWidth - 1.0f, 2.0f * (y + 0.5f) / kHeight - 1.0f,
                          frame.depth[i], 1.0f);
      const glm::vec4 world = to_world * ndc;
      const float ahead = world.z / world.w + 400.0f;
      farthest = std::max(farthest, ahead);
      if (ahead > 0.5f * table.tile_size_m * float(table.height - 4)) continue;  // beyond reach
      const glm::vec2 u = glm::vec2(world.x, world.z) / world.w / table.tile_size_m;
      // The four tiles' centres, in half tiles, span floor(2u) - 1 .. floor(2u) + 1.
      const glm::ivec2 centre(glm::floor(2.0f * u));
      if (glm::any(glm::lessThan(centre - 1, lo)) || glm::any(glm::greaterThan(centre + 1, hi))) ++outside;
    }
  }
  EXPECT_GT(water, 1000u);
  EXPECT_GT(farthest, 500.0f) << "the view reaches far down the river";
  EXPECT_EQ(outside, 0u) << "of " << water << " water pixels";
}

// The host's own projections: reverse-Z with an infinite far plane renders the water of a
// standard projection, and a jittered projection moves it by the jitter.
TEST_F(RenderTest, ReverseZInfiniteAndJitteredProjectionsRenderTheSameWater) {
  const auto standard_at = [this](double time) {
    return camera_view(world_->scene_camera(time), {kWidth, kHeight});
  };
  const std::vector<Frame> standard = render_views(0, 2, kWidth, kHeight, standard_at);
  ASSERT_EQ(standard.size(), 2u);
  renderer_.reset();
  // Reverse-Z, infinite far plane: depth = near / distance.
  const auto reverse_at = [&](double time) {
    View view = standard_at(time);
    const Camera camera = world_->scene_camera(time);
    const float f = 1.0f / std::tan(0.5f * glm::radians(camera.fov_y_deg));
    view.projection = glm::mat4(0.0f);
    view.projection[0][0] = f * kHeight / kWidth;
    view.projection[1][1] = -f;
    view.projection[2][3] = -1.0f;
    view.projection[3][2] = camera.near_plane;
    return view;
  };
  const std::vector<Frame> reverse = render_views(0, 2, kWidth, kHeight, reverse_at);
  ASSERT_EQ(reverse.size(), 2u);
  size_t water = 0;
  size_t mask_differs = 0;
  size_t colour_differs = 0;  // beyond the golden frames' tolerance
  for (size_t i = 0; i < standard[1].water_mask.size(); ++i) {
    if (standard[1].water_mask[i] != reverse[1].water_mask[i]) ++mask_differs;
    water += standard[1].water_mask[i] == 1.0f ? 1 : 0;
    for (int c = 0; c < 3; ++c) {
      const float golden = standard[1].rgba[i * 4 + c];
      if (std::abs(golden - reverse[1].rgba[i * 4 + c]) > 0.02f + 0.02f * std::abs(golden)) {
        ++colour_differs;
        break;
      }
    }
  }
  const size_t pixels = standard[1].water_mask.size();
  ASSERT_GT(water, 5000u);
  EXPECT_LT(mask_differs, water / 100) << "the same water pixels";
  EXPECT_LE(colour_differs, pixels / 200) << "the same colours, of " << pixels << " pixels";
  EXPECT_EQ(standard[1].flow_texture, reverse[1].flow_texture) << "the same particles";
  EXPECT_EQ(reverse[1].depth[4 * kWidth + kWidth / 2], 0.0f) << "the sky at reverse-Z's far";

  renderer_.reset();
  // Jitter of one pixel to the right: the clip-space offset 2 / width in x.
  const auto jittered_at = [&](double time) {
    View view = standard_at(time);
    view.projection[2][0] -= 2.0f / kWidth;  // clip x gains -z * (2 / width): +1 pixel
    return view;
  };
  const std::vector<Frame> jittered = render_views(0, 2, kWidth, kHeight, jittered_at);
  ASSERT_EQ(jittered.size(), 2u);
  size_t shifted_same = 0;
  size_t unshifted_same = 0;
  size_t counted = 0;
  for (uint32_t y = 0; y < kHeight; ++y) {
    for (uint32_t x = 1; x < kWidth; ++x) {
      const size_t i = size_t{y} * kWidth + x;
      ++counted;
      if (jittered[1].water_mask[i] == standard[1].water_mask[i - 1]) ++shifted_same;
      if (jittered[1].water_mask[i] == standard[1].water_mask[i]) ++unshifted_same;
    }
  }
  EXPECT_GT(shifted_same, counted - counted / 500) << "the water moved one pixel right";
  EXPECT_LT(unshifted_same, shifted_same);
}

TEST_F(RenderTest, FramesAreDeterministicWhateverTheFirstFrame) {
  const std::vector<Frame> run = render(0, 4);
  ASSERT_TRUE(context_->wait_idle().ok());
  // A fresh renderer starting at frame 3, as a shard of a capture would:
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  for (uint32_t frame = 0; frame < 3; ++frame) {  // it replays the simulation without rendering
    const View view = camera_view(world_->scene_camera(frame / 30.0), {kWidth, kHeight});
    ASSERT_TRUE(renderer_->simulate(view, frame / 30.0).ok());
  }
  const std::vector<Frame> shard = render(3, 4);
  ASSERT_EQ(run.size(), 4u);
  ASSERT_EQ(shard.size(), 1u);
  EXPECT_EQ(std::memcmp(run[3].rgba.data(), shard[0].rgba.data(), run[3].rgba.size() * sizeof(float)), 0);
  EXPECT_EQ(run[3].depth, shard[0].depth);
  EXPECT_EQ(run[3].flow_texture, shard[0].flow_texture) << "the particles differ";
  EXPECT_EQ(run[3].particle_aux, shard[0].particle_aux);
  EXPECT_NE(run[0].rgba, run[3].rgba) << "the camera moves: frames must differ";
}

TEST_F(RenderTest, ResizeBetweenFramesKeepsFramesInFlightValid) {
  ASSERT_EQ(render(0, 3).size(), 3u);
  ASSERT_TRUE(renderer_->resize({160, 90}).ok());
  EXPECT_EQ(renderer_->readback_bytes(ReadbackImage::kColor), 160u * 90u * 8u);
  const std::vector<Frame> small = render(3, 6, 160, 90);
  ASSERT_EQ(small.size(), 3u);
  EXPECT_NE(particle_field(*renderer_).occluders(), nullptr) << "the new particles see the world";
  const float* sky = small[0].pixel(80, 2);
  EXPECT_GT(sky[2], sky[0]);
  EXPECT_EQ(small[0].depth[2 * 160 + 80], 1.0f);
  EXPECT_LT(small[0].depth[88 * 160 + 80], 0.999f);
  EXPECT_FALSE(renderer_->resize({0, 90}).ok());
}

TEST_F(RenderTest, FrameGraphRunsWaterPassesOnly) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  const std::string dump = renderer_->dump_frame_graph();
  // Static data is uploaded by a one-off graph: the frame graph's upload pass carries only the
  // flow texture and the particles' aux data, every frame. Then the mirrored world (the host's
  // callback), the tile table, the water over the host's colour, and the copies for the host;
  // no world of our own.
  EXPECT_EQ(dump.find("pass scene"), std::string::npos) << dump;
  size_t previous = 0;
  for (const char* pass : {"pass upload", "pass reflection", "pass flow tiles", "pass flow", "pass readback"}) {
    const size_t at = dump.find(pass);
    ASSERT_NE(at, std::string::npos) << pass << "\n" << dump;
    EXPECT_GE(at, previous) << pass << " out of order\n" << dump;
    previous = at;
  }
  EXPECT_EQ(dump.find("river vertices"), std::string::npos) << "static data is not uploaded per frame\n" << dump;
  EXPECT_NE(renderer_->dump_frame_graph_graphviz().find("digraph"), std::string::npos);
}

TEST_F(RenderTest, ReadbackIsAskedForPerImage) {
  // Colour alone: copied, with the plain water pipeline (no AOV attachments).
  CreateInfo info = make_create_info(kWidth, kHeight);
  info.readback_images = readback_bit(ReadbackImage::kColor);
  ASSERT_TRUE(create_renderer(info).ok());
  std::string dump = renderer_->dump_frame_graph();
  EXPECT_NE(dump.find("readback colour"), std::string::npos) << dump;
  EXPECT_EQ(dump.find("readback water mask"), std::string::npos) << dump;
  EXPECT_EQ(dump.find("water normal"), std::string::npos) << "no AOV attachments\n" << dump;
  // The normal: the AOV attachments come in, and only the normal is copied.
  info.readback_images = readback_bit(ReadbackImage::kNormal);
  ASSERT_TRUE(create_renderer(info).ok());
  dump = renderer_->dump_frame_graph();
  EXPECT_NE(dump.find("readback water normal"), std::string::npos) << dump;
  EXPECT_EQ(dump.find("readback colour"), std::string::npos) << dump;
  EXPECT_EQ(dump.find("readback reflection sample"), std::string::npos) << dump;
  // Bits past the images are refused by value.
  info.readback_images = 1u << 12;
  const Status status = create_renderer(info);
  ASSERT_FALSE(status.ok());
  EXPECT_NE(status.message().find("readback_images 0x1000"), std::string::npos) << status.message();
}

TEST_F(RenderTest, BadCreateInfoIsReportedNotCrashed) {
  CreateInfo info = make_create_info(0, kHeight);
  Status status = Renderer::create(info, &renderer_);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("extent"), std::string::npos) << status.message();

  info = make_create_info(context_->report().max_image_dimension_2d + 1, 16);
  status = Renderer::create(info, &renderer_);
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.message().find("device limit"), std::string::npos) << status.message();

  info = make_create_info(kWidth, kHeight);
  info.get_instance_proc_addr = nullptr;
  EXPECT_FALSE(Renderer::create(info, &renderer_).ok());

  // A host that created its device without shaderClipDistance: named, not crashed at record.
  RequiredDeviceFeatures without_clip = required_device_features();
  without_clip.features2.features.shaderClipDistance = VK_FALSE;
  without_clip.link();
  info = make_create_info(kWidth, kHeight);
  info.enabled_features = &without_clip.features2;
  status = Renderer::create(info, &renderer_);
  EXPECT_FALSE(status.ok());
  EXPECT_EQ(status.code(), VK_ERROR_FEATURE_NOT_PRESENT);
  EXPECT_NE(status.message().find("shaderClipDistance"), std::string::npos) << status.message();
  info = make_create_info(kWidth, kHeight);
  info.enabled_features = nullptr;
  status = Renderer::create(info, &renderer_);
  EXPECT_NE(status.message().find("enabled_features"), std::string::npos) << status.message();

  info = make_create_info(kWidth, kHeight);
  info.queue_family_index = 99;
  status = Renderer::create(info, &renderer_);
  EXPECT_NE(status.message().find("queue_family_index 99"), std::string::npos) << status.message();
  EXPECT_EQ(renderer_, nullptr);
}

// Each bad host image or view is refused by record() or update() with a message naming the
// field, before any command is recorded: the command buffer stays empty.
TEST_F(RenderTest, BadHostImagesAndViewsAreRefusedByName) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  HostTargets targets;
  ASSERT_TRUE(create_host_targets(*context_, VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT,
                                  {kWidth, kHeight}, {0, 0, VK_IMAGE_LAYOUT_GENERAL}, &targets).ok());
  const View good = camera_view(world_->scene_camera(0.0), {kWidth, kHeight});
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  ASSERT_TRUE(context_->begin_slot(0, &cmd).ok());
  ASSERT_TRUE(renderer_->begin_frame(0).ok());

  View bad = good;
  bad.view[0][0] = std::nanf("");
  Status status = renderer_->update(bad, 0.0);
  EXPECT_NE(status.message().find("View::view has a non-finite"), std::string::npos) << status.message();
  bad = good;
  bad.view = glm::mat4(0.0f);
  status = renderer_->update(bad, 0.0);
  EXPECT_NE(status.message().find("View::view is singular"), std::string::npos) << status.message();
  bad = good;
  bad.projection = glm::orthoRH_ZO(-10.0f, 10.0f, -10.0f, 10.0f, 0.1f, 100.0f);
  status = renderer_->update(bad, 0.0);
  EXPECT_NE(status.message().find("View::projection is not a perspective"), std::string::npos) << status.message();
  bad = good;
  bad.viewport.extent = {kWidth / 2, kHeight};
  status = renderer_->update(bad, 0.0);
  EXPECT_NE(status.message().find("View::viewport extent 160x180"), std::string::npos) << status.message();
  EXPECT_EQ(renderer_->next_frame(), 0u) << "a refused view advances nothing";
  ASSERT_TRUE(renderer_->update(good, 0.0).ok());

  const auto refused = [&](FrameInputs inputs, const char* expected) {
    for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
      HostBuffer buffer;
      ASSERT_TRUE(context_->create_readback_buffer(renderer_->readback_bytes(static_cast<ReadbackImage>(i)), &buffer).ok());
      inputs.readback.buffers[i] = buffer.buffer;
    }
    const Status s = renderer_->record(cmd, inputs);
    EXPECT_FALSE(s.ok());
    EXPECT_NE(s.message().find(expected), std::string::npos) << s.message();
    EXPECT_EQ(s.code(), Status::kGenericError) << "an argument error, not a Vulkan result";
  };
  FrameInputs inputs;
  inputs.color = targets.color;
  inputs.depth = targets.depth;
  inputs.color.final = {};  // layout UNDEFINED
  refused(inputs, "FrameInputs::color.final.layout");
  inputs.color = targets.color;
  inputs.depth.format = VK_FORMAT_D24_UNORM_S8_UINT;
  refused(inputs, "siviflow::Renderer: FrameInputs::depth.format VK_FORMAT_D24_UNORM_S8_UINT "
                  "differs from the configured VK_FORMAT_D32_SFLOAT");
  inputs.depth = targets.depth;
  inputs.color.extent = {kWidth - 1, kHeight};
  refused(inputs, "FrameInputs::color.extent 319x180 does not contain");
  inputs.color = targets.color;
  inputs.depth.view = VK_NULL_HANDLE;
  refused(inputs, "FrameInputs::depth needs an image and a view");
  inputs.depth = targets.depth;
  inputs.depth.usage &= ~VkImageUsageFlags{VK_IMAGE_USAGE_SAMPLED_BIT};  // the water reads it
  refused(inputs, "siviflow::Renderer: FrameInputs::depth.usage VK_IMAGE_USAGE_TRANSFER_SRC_BIT | "
                  "VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT lacks VK_IMAGE_USAGE_SAMPLED_BIT");
  inputs.depth = targets.depth;
  inputs.color.usage &= ~VkImageUsageFlags{VK_IMAGE_USAGE_TRANSFER_SRC_BIT};  // the refraction copy
  refused(inputs, "lacks VK_IMAGE_USAGE_TRANSFER_SRC_BIT");
  ASSERT_TRUE(context_->end_slot_and_submit(0).ok());  // an empty command buffer is fine
  ASSERT_TRUE(context_->wait_slot(0).ok());
}

TEST_F(RenderTest, RecordOutOfOrderIsAnError) {
  ASSERT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());
  const View view = camera_view(world_->scene_camera(0.0), {kWidth, kHeight});
  EXPECT_FALSE(renderer_->update(view, 0.0).ok());  // before begin_frame
  EXPECT_FALSE(renderer_->begin_frame(5).ok());                              // slot out of range
}

}  // namespace
}  // namespace siviflow::testing
