// Injected Vulkan faults through the renderer's private device table: the k-th call that creates
// device memory, a buffer, an image or view, a sampler, a shader module, a pipeline or its
// layout, a descriptor set layout, pool or sets fails with VK_ERROR_OUT_OF_DEVICE_MEMORY (sets:
// VK_ERROR_OUT_OF_POOL_MEMORY), for every k in turn, during create, during resize and during the
// first frames. Each returns a status carrying the result and naming the call; a failed create
// leaves nothing it made alive, a failed resize a renderer that renders again after a resize,
// a failed frame one whose next frame renders; destroyed, none leaves anything alive. The
// validation layer watches every run.
#include <array>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "device_call_faults.h"
#include "render_frames.h"

namespace siviflow::testing {
namespace {

namespace faults = device_call_faults;

class DeviceFaultTest : public RenderTest {
 protected:
  void TearDown() override {
    faults::state.fail_at = -1;
    RenderTest::TearDown();
  }
  // The world of the default scene and a renderer info whose device calls are watched.
  CreateInfo watched_info() {
    EXPECT_TRUE(create_renderer(make_create_info(kWidth, kHeight)).ok());  // the world
    renderer_.reset();
    CreateInfo info = make_create_info(kWidth, kHeight);
    faults::install(info.get_device_proc_addr);
    info.get_device_proc_addr = &faults::get_device_proc_addr;
    info.reflection = &World::draw_reflection;
    info.reflection_user = world_.get();
    return info;
  }
  // Makes the k-th watched call from now fail.
  static void fail_at(int64_t k) {
    faults::state.calls = 0;
    faults::state.failed_call.clear();
    faults::state.fail_at = k;
  }
  static bool injected() { return !faults::state.failed_call.empty(); }
};

void expect_named_fault(const Status& status, const char* stage, int64_t k) {
  const bool pool = faults::state.failed_call == "vkAllocateDescriptorSets";
  EXPECT_EQ(status.code(), pool ? VK_ERROR_OUT_OF_POOL_MEMORY : VK_ERROR_OUT_OF_DEVICE_MEMORY)
      << stage << ", call " << k << " (" << faults::state.failed_call << "): " << status.message();
  EXPECT_NE(status.message().find(faults::state.failed_call), std::string::npos)
      << stage << ", call " << k << ": the message names " << faults::state.failed_call << ": "
      << status.message();
}

TEST_F(DeviceFaultTest, CreateFailsCleanlyAtEveryDeviceCall) {
  const CreateInfo info = watched_info();
  int64_t k = 0;
  for (;; ++k) {
    renderer_.reset();
    ASSERT_EQ(faults::state.alive, (std::array<int64_t, faults::kKindCount>{}))
        << "before call " << k;
    fail_at(k);
    const Status status = Renderer::create(info, &renderer_);
    if (!injected()) {  // create made fewer than k + 1 watched calls: it succeeded
      ASSERT_TRUE(status.ok()) << status.message();
      break;
    }
    expect_named_fault(status, "create", k);
    EXPECT_EQ(renderer_, nullptr);
    EXPECT_EQ(faults::state.alive, (std::array<int64_t, faults::kKindCount>{}))
        << "create failing at call " << k << " (" << faults::state.failed_call
        << ") left objects alive";
  }
  std::printf("create: %lld injection points, each refused cleanly\n", static_cast<long long>(k));
  EXPECT_GT(k, 40) << "create makes many watched calls; each was made to fail";
  faults::state.fail_at = -1;
  EXPECT_EQ(render(0, 2).size(), 2u) << "a create after the faults renders";
  renderer_.reset();
  EXPECT_EQ(faults::state.alive, (std::array<int64_t, faults::kKindCount>{}));
}

TEST_F(DeviceFaultTest, ResizeFailsCleanlyAndAResizeAfterItRenders) {
  // A failed resize refuses frames until a resize succeeds (renderer.h); then it renders at
  // the new size, and back at the old one.
  const CreateInfo info = watched_info();
  ASSERT_TRUE(Renderer::create(info, &renderer_).ok());
  ASSERT_EQ(render(0, 2).size(), 2u);
  const VkExtent2D half{kWidth / 2, kHeight / 2};
  int64_t k = 0;
  uint32_t frame = 2;
  for (;; ++k) {
    fail_at(k);
    Status status = renderer_->resize(half);
    faults::state.fail_at = -1;
    if (!injected()) {
      ASSERT_TRUE(status.ok()) << status.message();
      break;
    }
    expect_named_fault(status, "resize", k);
    status = renderer_->begin_frame(0);
    EXPECT_FALSE(status.ok()) << "frames are refused after a failed resize";
    EXPECT_NE(status.message().find("resize again"), std::string::npos) << status.message();
    ASSERT_TRUE(renderer_->resize(half).ok()) << "a resize after the fault at call " << k;
    ASSERT_EQ(render(frame, frame + 1, half.width, half.height).size(), 1u);
    ASSERT_TRUE(renderer_->resize({kWidth, kHeight}).ok());
    ASSERT_EQ(render(frame + 1, frame + 2).size(), 1u);
    frame += 2;
  }
  std::printf("resize: %lld injection points, each refused cleanly\n", static_cast<long long>(k));
  EXPECT_GT(k, 5);
  EXPECT_EQ(render(frame, frame + 2, half.width, half.height).size(), 2u);
  renderer_.reset();
  EXPECT_EQ(faults::state.alive, (std::array<int64_t, faults::kKindCount>{}))
      << "destroyed after the faults, the renderer leaves nothing alive";
}

// One frame at `time` through slot 0 (host targets of its own, no readback): a failed update or
// record is returned and its command buffer discarded, as a host would (the next begin_slot
// resets it); a whole frame is submitted and waited for.
Status one_frame(HeadlessContext& context, World& world, Renderer& renderer, HostTargets* targets,
                 double time) {
  const View view = camera_view(world.scene_camera(time), {kWidth, kHeight});
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  SIVIFLOW_TRY(context.begin_slot(0, &cmd));
  SIVIFLOW_TRY(renderer.begin_frame(0));
  SIVIFLOW_TRY(renderer.update(view, time));
  SIVIFLOW_TRY(record_world_and_water(cmd, 0, world, renderer, view, time, {}, targets));
  SIVIFLOW_TRY(context.end_slot_and_submit(0));
  return context.wait_slot(0);
}

TEST_F(DeviceFaultTest, FirstFramesFailCleanlyAndTheNextOnesRender) {
  // Every watched call of the first three frames made to fail in turn, each in a fresh renderer;
  // the frame after the one that failed renders.
  CreateInfo info = watched_info();
  info.readback_images = 0;
  HostTargets targets;
  ASSERT_TRUE(create_sampled_targets({kWidth, kHeight}, &targets).ok());
  int64_t k = 0;
  for (;; ++k) {
    renderer_.reset();
    faults::state.fail_at = -1;
    ASSERT_TRUE(Renderer::create(info, &renderer_).ok());
    fail_at(k);
    Status status;
    uint32_t frame = 0;
    for (; frame < 3 && status.ok(); ++frame) {
      status = one_frame(*context_, *world_, *renderer_, &targets, frame / 30.0);
    }
    faults::state.fail_at = -1;
    if (!injected()) {
      ASSERT_TRUE(status.ok()) << status.message();
      break;
    }
    expect_named_fault(status, "frame", k);
    status = one_frame(*context_, *world_, *renderer_, &targets, frame / 30.0);
    EXPECT_TRUE(status.ok()) << "the frame after a fault at call " << k << ": " << status.message();
  }
  std::printf("first frames: %lld injection points, each reported\n", static_cast<long long>(k));
  EXPECT_GT(k, 0) << "the first frames make watched calls";
  renderer_.reset();
  EXPECT_EQ(faults::state.alive, (std::array<int64_t, faults::kKindCount>{}));
}

// A material and a debug view switched to after create are compiled by the frame that first draws
// with them: every watched call of that frame made to fail in turn is reported, and the frame
// after it renders with them.
TEST_F(DeviceFaultTest, AMaterialSwitchedToFailsItsFirstFrameCleanlyAndTheNextRenders) {
  CreateInfo info = watched_info();
  info.readback_images = 0;
  HostTargets targets;
  ASSERT_TRUE(create_sampled_targets({kWidth, kHeight}, &targets).ok());
  WaterLook look;
  look.material = WaterMaterial::kFlowMap;
  int64_t k = 0;
  for (;; ++k) {
    renderer_.reset();
    faults::state.fail_at = -1;
    ASSERT_TRUE(Renderer::create(info, &renderer_).ok());
    ASSERT_TRUE(one_frame(*context_, *world_, *renderer_, &targets, 0.0).ok());
    ASSERT_TRUE(renderer_->set_look(look).ok());
    ASSERT_TRUE(renderer_->set_debug_view(DebugView::kFlowDirection).ok());
    fail_at(k);
    Status status = one_frame(*context_, *world_, *renderer_, &targets, 1 / 30.0);
    faults::state.fail_at = -1;
    if (!injected()) {
      ASSERT_TRUE(status.ok()) << status.message();
      break;
    }
    expect_named_fault(status, "frame", k);
    if (faults::state.failed_call == "vkCreateGraphicsPipelines") {
      EXPECT_NE(status.message().find("water material flowmap with the debug views"),
                std::string::npos)
          << status.message();
    }
    status = one_frame(*context_, *world_, *renderer_, &targets, 2 / 30.0);
    EXPECT_TRUE(status.ok()) << "the frame after a fault at call " << k << ": " << status.message();
  }
  std::printf("switched material's frame: %lld injection points, each reported\n",
              static_cast<long long>(k));
  EXPECT_GE(k, 3) << "the frame compiles a pipeline (2 shader modules and the pipeline)";
  renderer_.reset();
  EXPECT_EQ(faults::state.alive, (std::array<int64_t, faults::kKindCount>{}));
}

}  // namespace
}  // namespace siviflow::testing
