// One river, many views: renderers that share a river (CreateInfo::share_river_with) render
// each view exactly as a renderer of its own would, in two images or side by side in one image
// (split screen by viewports), with one flow solve between them; an obstacle added through one
// re-routes the other's flow. And several rivers: a scene's rivers, one renderer each, drawn
// over one world, each with its own flow.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <memory>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include "gltf_test_files.h"
#include "gpu_test.h"
#include "run_command.h"
#include "default_river.h"
#include "renderer_inspect.h"
#include "river_simulation.h"
#include "siviflow/host_frame.h"
#include "siviflow/scene_river.h"

namespace siviflow::testing {
namespace {

namespace fs = std::filesystem;

constexpr uint32_t kWidth = 320;
constexpr uint32_t kHeight = 180;
constexpr uint32_t kFrames = 3;

// One view: its renderer, its camera time offset, where it lies in which host images.
struct Pane {
  Renderer* renderer = nullptr;
  double camera_delay = 0.0;  // seconds ahead on the scene's camera path
  HostTargets* targets = nullptr;
  VkRect2D viewport{};
  bool draws_world = true;  // false: another river over the world a pane before drew
  HostBuffer colour;  // read back: the view's pixels
  HostBuffer flow;    // read back: its flow texture
  HostBuffer mask;    // read back when the renderer was made with the water mask
};

// A host's river handed to the renderer with a river_copied callback, which counts its calls,
// overwrites the arrays with what no river holds and frees them: a renderer that read them
// after would draw another river (or, under AddressSanitizer, read freed memory).
struct CopiedRiver {
  SceneRiverData data;  // none: the built-in river, with the callback still set
  int calls = 0;
  static void spoil_and_release(void* user) {
    auto* river = static_cast<CopiedRiver*>(user);
    ++river->calls;
    RiverMesh& mesh = river->data.mesh;
    std::fill(mesh.positions.begin(), mesh.positions.end(), glm::vec3(NAN));
    std::fill(mesh.indices.begin(), mesh.indices.end(), UINT32_MAX);
    std::fill(mesh.depth.begin(), mesh.depth.end(), -1.0f);
    std::fill(river->data.slope.begin(), river->data.slope.end(), -1.0f);
    SceneRiverData::release_arrays(&river->data);
  }
};

class SharedRiverTest : public GpuTest {
 protected:
  std::unique_ptr<Renderer> make(VkExtent2D extent, const Renderer* share = nullptr,
                                 const SceneFile* scene = nullptr, uint32_t river = 0,
                                 CopiedRiver* copied = nullptr) {
    if (world_ == nullptr) {
      WorldCreateInfo world_info =
          context_->world_create_info(VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_D32_SFLOAT);
      world_info.scene = scene;
      EXPECT_TRUE(World::create(world_info, &world_).ok());
    }
    CreateInfo info = make_create_info(extent.width, extent.height);
    info.readback_images = readback_bit(ReadbackImage::kColor) | readback_bit(ReadbackImage::kFlowTexture);
    if (scene != nullptr) info.readback_images |= readback_bit(ReadbackImage::kWaterMask);
    info.reflection = &World::draw_reflection;
    info.reflection_user = world_.get();
    info.share_river_with = share;
    SceneRiverData data;  // read by create() only
    WaterRiver water;
    if (scene != nullptr) {
      const Status read = scene_river_data(scene, river, &data);
      EXPECT_TRUE(read.ok()) << read.message();
      water = data.river();
      info.river = &water;
    }
    if (copied != nullptr) {
      water = copied->data.river();
      info.river = copied->data.mesh.positions.empty() ? nullptr : &water;
      info.river_copied = &CopiedRiver::spoil_and_release;
      info.river_copied_user = copied;
    }
    std::unique_ptr<Renderer> renderer;
    Status status = Renderer::create(info, &renderer);
    // The world hides water from a river's views; given once, through the river's first view.
    if (status.ok() && share == nullptr) status = renderer->set_occluders(world_->occluders());
    EXPECT_TRUE(status.ok()) << status.message();
    return renderer;
  }

  HostTargets* targets(VkExtent2D extent) {
    targets_.push_back(std::make_unique<HostTargets>());
    EXPECT_TRUE(create_sampled_targets(extent, targets_.back().get()).ok());
    return targets_.back().get();
  }

  void add_readback(Pane* pane) {
    ASSERT_TRUE(context_->create_readback_buffer(
        pane->renderer->readback_bytes(ReadbackImage::kColor), &pane->colour).ok());
    ASSERT_TRUE(context_->create_readback_buffer(
        pane->renderer->readback_bytes(ReadbackImage::kFlowTexture), &pane->flow).ok());
    ASSERT_TRUE(context_->create_readback_buffer(
        pane->renderer->readback_bytes(ReadbackImage::kWaterMask), &pane->mask).ok());
  }

  // Frames 0 .. kFrames-1 of every pane, all in one command buffer per frame: the world then the
  // water of each view in turn.
  void render(std::vector<Pane*> panes) {
    for (Pane* pane : panes) add_readback(pane);
    for (uint32_t frame = 0; frame < kFrames; ++frame) {
      const double time = frame / 30.0;
      VkCommandBuffer cmd = VK_NULL_HANDLE;
      ASSERT_TRUE(context_->begin_slot(0, &cmd).ok());
      ASSERT_TRUE(world_->begin_frame(0).ok());
      for (Pane* pane : panes) {
        const View view = pane_view(*pane, time);
        ASSERT_TRUE(pane->renderer->begin_frame(0).ok());
        Status status = pane->renderer->update(view, time);
        ASSERT_TRUE(status.ok()) << status.message();
        ExternalImage color = pane->targets->color;
        ExternalImage depth = pane->targets->depth;
        if (pane->draws_world) {
          color.final = {VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                         VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                         VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
          depth.final = {VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                         VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                         VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL};
          status = world_->record(cmd, view, time, color, depth);
          ASSERT_TRUE(status.ok()) << status.message();
        } else {
          color.final = color.current;
          depth.final = depth.current;
        }
        FrameInputs inputs;
        inputs.color = pane->targets->color;
        inputs.depth = pane->targets->depth;
        inputs.color.current = color.final;
        inputs.depth.current = depth.final;
        inputs.readback[ReadbackImage::kColor] = pane->colour.buffer;
        inputs.readback[ReadbackImage::kFlowTexture] = pane->flow.buffer;
        inputs.readback[ReadbackImage::kWaterMask] = pane->mask.buffer;
        status = pane->renderer->record(cmd, inputs);
        ASSERT_TRUE(status.ok()) << status.message();
        pane->targets->color.current = pane->targets->color.final;
        pane->targets->depth.current = pane->targets->depth.final;
      }
      ASSERT_TRUE(context_->end_slot_and_submit(0).ok());
      ASSERT_TRUE(context_->wait_slot(0).ok());
    }
  }

  View pane_view(const Pane& pane, double time) const {
    View view = camera_view(world_->scene_camera(time + pane.camera_delay), pane.viewport.extent);
    view.viewport = pane.viewport;
    return view;
  }


  std::vector<std::unique_ptr<HostTargets>> targets_;
};

// Pixels of two panes' read-back colours that differ, and by how much at most (per channel).
size_t differing_pixels(const Pane& a, const Pane& b, float* largest = nullptr) {
  const size_t values = size_t{a.viewport.extent.width} * a.viewport.extent.height * 4;
  const auto* pa = static_cast<const uint16_t*>(a.colour.data);
  const auto* pb = static_cast<const uint16_t*>(b.colour.data);
  size_t count = 0;
  float worst = 0.0f;
  for (size_t i = 0; i < values; i += 4) {
    bool differs = false;
    for (size_t c = i; c < i + 4; ++c) {
      const float d = std::abs(glm::unpackHalf1x16(pa[c]) - glm::unpackHalf1x16(pb[c]));
      worst = std::max(worst, d);
      differs = differs || d > 0.0f;
    }
    count += differs ? 1 : 0;
  }
  if (largest != nullptr) *largest = worst;
  return count;
}

TEST_F(SharedRiverTest, OnUnifiedMemoryTheFlowReadsTheMeshFromTheGpuBuffers) {
  // Lavapipe's memory is the host's, and cached: a long river's mesh is held once, not twice.
  // (A discrete GPU's is not the host's: there the flow keeps its own, and the rest holds.)
  const std::unique_ptr<Renderer> first = make({64, 48});
  ASSERT_NE(first, nullptr);
  if (context_->report().driver_id == VK_DRIVER_ID_MESA_LLVMPIPE) {
    EXPECT_TRUE(RendererInspector::flow_reads_gpu_mesh(*first));
  }
  const std::unique_ptr<Renderer> second = make({64, 48}, first.get());
  ASSERT_NE(second, nullptr);
  EXPECT_EQ(flow_field(*second).positions.data(), flow_field(*first).positions.data());
  // What the particles read is the procedural river's mesh, from those buffers.
  const ProceduralRiver procedural(default_river_params());
  RiverInput input;
  ASSERT_TRUE(procedural_river_input(procedural, &input).ok());
  const RiverFlowField& field = flow_field(*first);
  ASSERT_EQ(field.positions.size(), input.surface.node_positions().size());
  EXPECT_TRUE(std::equal(field.positions.begin(), field.positions.end(),
                         input.surface.node_positions().begin()));
  EXPECT_TRUE(std::equal(field.indices.begin(), field.indices.end(),
                         input.surface.triangles().begin()));
}

TEST_F(SharedRiverTest, AHostMayFreeItsRiverOnceTheRendererHasCopiedIt) {
  const VkExtent2D extent{kWidth, kHeight};
  CopiedRiver copied;
  ASSERT_TRUE(scene_river_data(nullptr, 0, &copied.data).ok());  // the built-in river, as a host's
  auto freed = make(extent, nullptr, nullptr, 0, &copied);
  ASSERT_NE(freed, nullptr);
  EXPECT_EQ(copied.calls, 1);
  EXPECT_TRUE(copied.data.mesh.positions.empty() && copied.data.slope.empty());
  auto kept = make(extent);
  Pane a{freed.get(), 0.0, targets(extent), {{0, 0}, extent}};
  Pane b{kept.get(), 0.0, targets(extent), {{0, 0}, extent}};
  render({&a});
  render({&b});
  EXPECT_EQ(differing_pixels(a, b), 0u) << "the freed river's renderer draws the same river";
  // The built-in river is the renderer's own: there is nothing of the host's to free.
  CopiedRiver none;
  EXPECT_NE(make({64, 48}, nullptr, nullptr, 0, &none), nullptr);
  EXPECT_EQ(none.calls, 0);
}

TEST_F(SharedRiverTest, TwoViewsInTwoImagesEqualEachAloneWithOneSolve) {
  const VkExtent2D extent{kWidth, kHeight};
  auto main = make(extent);
  auto probe = make(extent, main.get());
  EXPECT_EQ(main->flow_solves(), 1u);
  EXPECT_EQ(probe->flow_solves(), 1u) << "the probe view shares the solve";
  Pane a{main.get(), 0.0, targets(extent), {{0, 0}, extent}};
  Pane b{probe.get(), 4.0, targets(extent), {{0, 0}, extent}};
  render({&a, &b});

  auto main_alone = make(extent);
  auto probe_alone = make(extent);
  Pane a_alone{main_alone.get(), 0.0, targets(extent), {{0, 0}, extent}};
  Pane b_alone{probe_alone.get(), 4.0, targets(extent), {{0, 0}, extent}};
  render({&a_alone});
  render({&b_alone});
  EXPECT_GT(differing_pixels(a, b), 1000u) << "two different views";
  EXPECT_EQ(differing_pixels(a, a_alone), 0u);
  EXPECT_EQ(differing_pixels(b, b_alone), 0u);
}

TEST_F(SharedRiverTest, SplitScreenViewsEqualEachAlone) {
  const VkExtent2D half{kWidth / 2, kHeight};
  HostTargets* screen = targets({kWidth, kHeight});
  auto left = make(half);
  auto right = make(half, left.get());
  Pane l{left.get(), 0.0, screen, {{0, 0}, half}};
  Pane r{right.get(), 4.0, screen, {{static_cast<int32_t>(kWidth / 2), 0}, half}};
  render({&l, &r});

  auto left_alone = make(half);
  auto right_alone = make(half);
  Pane l_alone{left_alone.get(), 0.0, targets(half), {{0, 0}, half}};
  Pane r_alone{right_alone.get(), 4.0, targets(half), {{0, 0}, half}};
  render({&l_alone, &r_alone});
  EXPECT_EQ(differing_pixels(l, l_alone), 0u);
  // Placed at an offset, the host's world rasterizes a hair differently (its full-screen sky
  // triangle a half-float step here and there, a few edge pixels more): within the goldens'
  // tolerance, the same view.
  float largest = 0.0f;
  const size_t differing = differing_pixels(r, r_alone, &largest);
  EXPECT_LT(differing, size_t{kWidth / 2} * kHeight / 20) << "the right half is the right view";
  EXPECT_LE(largest, 0.02f);
}

TEST_F(SharedRiverTest, ObstacleAddedThroughOneViewReroutesTheOther) {
  const VkExtent2D extent{kWidth, kHeight};
  auto main = make(extent);
  auto probe = make(extent, main.get());
  Pane before{probe.get(), 0.0, targets(extent), {{0, 0}, extent}};
  render({&before});
  std::vector<uint8_t> flow_before(static_cast<const uint8_t*>(before.flow.data),
                                   static_cast<const uint8_t*>(before.flow.data) +
                                       probe->readback_bytes(ReadbackImage::kFlowTexture));
  // A boat where the probe looks, added through the main view's renderer.
  WaterObstacle boat;
  const Camera camera = world_->scene_camera((kFrames - 1) / 30.0);
  boat.centre = {camera.target.x, 0.0f, camera.target.z};
  boat.radius = 2.5f;
  uint32_t id = 0;
  ASSERT_TRUE(main->add_obstacle(boat, &id).ok());
  EXPECT_EQ(probe->flow_solves(), 1u) << "incremental, not a new solve";
  auto probe_again = make(extent, main.get());  // same particles as `before` from frame 0
  Pane after{probe_again.get(), 0.0, targets(extent), {{0, 0}, extent}};
  render({&after});
  const auto* flow_after = static_cast<const uint8_t*>(after.flow.data);
  size_t changed = 0;
  for (size_t i = 0; i < flow_before.size(); ++i) changed += flow_before[i] != flow_after[i] ? 1 : 0;
  EXPECT_GT(changed, 1000u) << "the shared flow goes round the boat";
  // Removed through the probe's renderer: the river is as before for every view.
  ASSERT_TRUE(probe->remove_obstacle(id).ok());
  EXPECT_FALSE(main->remove_obstacle(id).ok()) << "one set of obstacles";
}

// Mean speed of a renderer's live particles (their flow as simulated).
double mean_particle_speed(const Renderer& renderer, size_t* count) {
  double sum = 0.0;
  *count = 0;
  for (const Particle& p : particle_field(renderer).particles()) {
    if (!p.live()) continue;
    sum += glm::length(p.flow);
    ++*count;
  }
  return *count == 0 ? 0.0 : sum / static_cast<double>(*count);
}

TEST_F(SharedRiverTest, TwoRiversOfASceneRenderEachWithItsOwnFlow) {
  // Two straight channels 8 m wide side by side, the right one carrying four times the water.
  const fs::path dir = fresh_test_dir("two_rivers");
  write_channel_gltf(dir / "slow.gltf", 61, 9, 8.0f, 1.0f, 0.0f, -9.0f);
  write_channel_gltf(dir / "fast.gltf", 61, 9, 8.0f, 1.0f, 0.0f, 9.0f);
  SceneFile scene;
  scene.path = (dir / "two_rivers.json").string();
  scene.rivers.resize(2);
  for (int i = 0; i < 2; ++i) {
    scene.rivers[i].source = SceneRiver::Source::kGltf;
    scene.rivers[i].gltf = (dir / (i == 0 ? "slow.gltf" : "fast.gltf")).string();
    scene.rivers[i].flow.discharge = i == 0 ? 4.0f : 16.0f;
  }
  scene.camera.keys = {{0.0, {0.0f, 30.0f, -12.0f}, {0.0f, 0.0f, 30.0f}}};
  const VkExtent2D extent{kWidth, kHeight};
  auto slow = make(extent, nullptr, &scene, 0);
  auto fast = make(extent, nullptr, &scene, 1);
  SceneRiverData none;
  const Status missing = scene_river_data(&scene, 2, &none);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.message().find("no river 2 (it has 2)"), std::string::npos) << missing.message();
  HostTargets* screen = targets(extent);
  Pane a{slow.get(), 0.0, screen, {{0, 0}, extent}};
  Pane b{fast.get(), 0.0, screen, {{0, 0}, extent}, false};
  render({&a, &b});

  // Both rivers drawn: each one's water where it is. Looking down +Z, +X is on the left of the
  // picture: the fast river (x = 9) on the left, the slow one on the right.
  double centre[2] = {};
  size_t water[2] = {};
  for (int i = 0; i < 2; ++i) {
    const auto* mask = static_cast<const float*>((i == 0 ? a : b).mask.data);
    for (size_t p = 0; p < size_t{kWidth} * kHeight; ++p) {
      if (mask[p] != 1.0f) continue;
      centre[i] += static_cast<double>(p % kWidth);
      ++water[i];
    }
    ASSERT_GT(water[i], 1000u) << "river " << i << " is drawn";
    centre[i] /= static_cast<double>(water[i]);
  }
  EXPECT_GT(centre[0], kWidth / 2.0);
  EXPECT_LT(centre[1], kWidth / 2.0);
  // Each with its own flow: the same channel, four times the discharge, four times the speed.
  size_t count[2] = {};
  const double slow_speed = mean_particle_speed(*slow, &count[0]);
  const double fast_speed = mean_particle_speed(*fast, &count[1]);
  ASSERT_GT(count[0], 50u);
  ASSERT_GT(count[1], 50u);
  EXPECT_NEAR(fast_speed / slow_speed, 4.0, 0.4);
  EXPECT_EQ(slow->flow_solves(), 1u);
  EXPECT_EQ(fast->flow_solves(), 1u);
}

}  // namespace
}  // namespace siviflow::testing
