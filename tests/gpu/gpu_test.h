// Fixture of every GPU test: a headless context on lavapipe with the validation layer and
// synchronization validation; any validation error fails the test, and a missing layer or a
// device other than llvmpipe is a failure, never a skip.
#pragma once

#include <cstdlib>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "siviflow/headless_context.h"
#include "siviflow/host_frame.h"
#include "siviflow/renderer.h"
#include "siviflow/scene_river.h"
#include "siviflow/world.h"

namespace siviflow::testing {

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override {
    HeadlessContextOptions options;
    options.enable_validation = true;
    options.require_validation = true;
    options.require_lavapipe = std::getenv("SIVIFLOW_EXPECT_LAVAPIPE") != nullptr;
    const Status status = HeadlessContext::create(options, &context_);
    ASSERT_TRUE(status.ok()) << status.message();
    ASSERT_TRUE(context_->report().validation_enabled);
  }

  void TearDown() override {
    renderer_.reset();  // their destruction is validated too
    world_.reset();
    if (context_ == nullptr) return;
    std::string messages;
    for (const std::string& message : context_->validation_errors()) messages += message + "\n";
    EXPECT_EQ(context_->validation_error_count(), 0u) << messages;
  }

  // Colour (color_format_) and depth (D32) images of `extent` for one host slot, the colour left
  // sampled after each frame.
  Status create_sampled_targets(VkExtent2D extent, HostTargets* out) {
    return create_host_targets(*context_, color_format_, VK_FORMAT_D32_SFLOAT, extent,
                               {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                                VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL},
                               out);
  }

  CreateInfo make_create_info(uint32_t width, uint32_t height) const {
    CreateInfo info = context_->renderer_create_info({width, height}, color_format_);
    info.depth_format = VK_FORMAT_D32_SFLOAT;
    info.frames_in_flight = 2;
    info.readback_images = kAllReadbackImages;
    return info;
  }

  // The built-in world of `scene` (null: the default scene) as the host's world (reflected
  // through the callback unless the info has a callback of its own), then the renderer of the
  // scene's first river, with the scene's look unless the info has one, and the world's ground
  // and objects as its occluders, as our tools give them.
  Status create_renderer(CreateInfo info, const SceneFile* scene = nullptr) {
    renderer_.reset();
    world_.reset();
    WorldCreateInfo world_info = context_->world_create_info(info.color_format, info.depth_format);
    world_info.frames_in_flight = info.frames_in_flight;
    world_info.scene = scene;
    world_info.enable_timing = time_world_;
    SIVIFLOW_TRY(World::create(world_info, &world_));
    SceneRiverData river;  // read by create() only
    WaterRiver water;
    if (scene != nullptr) {
      SIVIFLOW_TRY(scene_river_data(scene, 0, &river));
      water = river.river();
      info.river = &water;
      if (info.look == nullptr) info.look = &scene->look;
    }
    if (info.reflection == nullptr) {
      info.reflection = &World::draw_reflection;
      info.reflection_user = world_.get();
    }
    SIVIFLOW_TRY(Renderer::create(info, &renderer_));
    return renderer_->set_occluders(world_->occluders());
  }

  std::unique_ptr<HeadlessContext> context_;
  VkFormat color_format_ = VK_FORMAT_R16G16B16A16_SFLOAT;  // the host's colour images
  bool time_world_ = false;  // create_renderer's world writes timestamps
  std::unique_ptr<World> world_;
  std::unique_ptr<Renderer> renderer_;
};

}  // namespace siviflow::testing
