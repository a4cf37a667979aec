// The GPU tests' frame loop: the built-in world then the water, through the embedding path,
// two frames in flight, every readback image collected per frame.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include <gtest/gtest.h>

#include "color_texels.h"
#include "gpu_test.h"
#include "siviflow/host_frame.h"

namespace siviflow::testing {

constexpr uint32_t kWidth = 320;
constexpr uint32_t kHeight = 180;

struct Frame {
  uint32_t width = 0;
  std::vector<float> rgba;   // linear, 4 floats per pixel (decoded from the host's format)
  std::vector<float> depth;  // window depth, 0 near .. 1 far
  std::vector<float> water_mask;
  std::vector<std::byte> flow_texture;  // as uploaded and read back
  std::vector<std::byte> particle_aux;
  std::vector<float> normal;  // RGBA per pixel: xyz the water normal, 0 off water
  std::vector<float> reflection;  // RGBA per pixel: the reflection sample, 0 off water
  std::vector<uint32_t> tile_table;  // RGBA32UI texels (shaders/shared.h)
  std::vector<float> foam;  // the foam's coverage, 0 none to 1 full, 0 off water

  const float* pixel(uint32_t x, uint32_t y) const { return &rgba[(size_t{y} * width + x) * 4]; }
};

class RenderTest : public GpuTest {
 protected:
  // Runs each frame's CPU part (begin_frame and update): on this thread, unless a test hands it
  // to another as a host's simulation thread would.
  std::function<void(const std::function<void()>&)> run_cpu_part_ =
      [](const std::function<void()>& part) { part(); };

  // Renders frames [first, end) with two frames in flight (one host slot, target and readback
  // set each; a slot is waited on only when it is reused) and returns them in order.
  std::vector<Frame> render(uint32_t first, uint32_t end, uint32_t width = kWidth,
                            uint32_t height = kHeight) {
    return render_views(first, end, width, height, [this, width, height](double time) {
      return camera_view(world_->scene_camera(time), {width, height});
    });
  }

  // Frame 3 of the default scene through a fresh renderer that `configure` (Status(Renderer&))
  // set up before its first frame.
  template <typename Configure>
  Frame fourth_frame_with(Configure configure) {
    renderer_.reset();
    world_.reset();
    Status status = create_renderer(make_create_info(kWidth, kHeight));
    EXPECT_TRUE(status.ok()) << status.message();
    if (!status.ok()) return Frame{};
    status = configure(*renderer_);
    EXPECT_TRUE(status.ok()) << status.message();
    std::vector<Frame> frames = render(0, 4);
    return frames.empty() ? Frame{} : frames.back();
  }

  // The same through the host's own view matrices at each time.
  template <typename ViewAt>
  std::vector<Frame> render_views(uint32_t first, uint32_t end, uint32_t width, uint32_t height,
                                  ViewAt view_at) {
    std::vector<Frame> frames;
    if (renderer_ == nullptr) {
      const Status status = create_renderer(make_create_info(width, height));
      EXPECT_TRUE(status.ok()) << status.message();
      if (!status.ok()) return frames;
    }
    struct Slot {
      HostTargets targets;
      HostBuffer readback[kReadbackImageCount];
      bool pending = false;
    };
    Slot slots[2];
    for (Slot& slot : slots) {
      EXPECT_TRUE(create_sampled_targets({width, height}, &slot.targets).ok());
      for (uint32_t i = 0; i < kReadbackImageCount; ++i) {
        EXPECT_TRUE(context_->create_readback_buffer(
            renderer_->readback_bytes(static_cast<ReadbackImage>(i)), &slot.readback[i]).ok());
      }
    }
    const auto collect = [&](Slot& slot) {
      Frame out;
      out.width = width;
      out.rgba = decode_color(color_format_, slot.readback[0].data, size_t{width} * height);
      const auto* depths = static_cast<const float*>(slot.readback[1].data);
      out.depth.assign(depths, depths + size_t{width} * height);
      const auto* mask = static_cast<const float*>(slot.readback[2].data);
      out.water_mask.assign(mask, mask + size_t{width} * height);
      const auto* flow = static_cast<const std::byte*>(slot.readback[3].data);
      out.flow_texture.assign(flow, flow + renderer_->readback_bytes(ReadbackImage::kFlowTexture));
      const auto* aux = static_cast<const std::byte*>(slot.readback[4].data);
      out.particle_aux.assign(aux, aux + renderer_->readback_bytes(ReadbackImage::kParticleAux));
      const auto* normal = static_cast<const float*>(slot.readback[5].data);
      out.normal.assign(normal, normal + size_t{width} * height * 4);
      const auto* reflection = static_cast<const float*>(slot.readback[6].data);
      out.reflection.assign(reflection, reflection + size_t{width} * height * 4);
      const auto* tiles = static_cast<const uint32_t*>(slot.readback[7].data);
      out.tile_table.assign(
          tiles, tiles + renderer_->readback_bytes(ReadbackImage::kTileTable) / sizeof(uint32_t));
      const auto* foam = static_cast<const float*>(slot.readback[8].data);
      out.foam.assign(foam, foam + size_t{width} * height);
      frames.push_back(std::move(out));
      slot.pending = false;
    };
    for (uint32_t frame = first; frame < end; ++frame) {
      const uint32_t index = frame % 2;
      Slot& slot = slots[index];
      VkCommandBuffer cmd = VK_NULL_HANDLE;
      EXPECT_TRUE(context_->begin_slot(index, &cmd).ok());  // waits for this slot's last frame
      if (slot.pending) collect(slot);
      const double time = frame / 30.0;
      const View view = view_at(time);
      Status begun;
      Status status;
      run_cpu_part_([&] {
        begun = renderer_->begin_frame(index);
        status = renderer_->update(view, time);
      });
      EXPECT_TRUE(begun.ok()) << begun.message();
      EXPECT_TRUE(status.ok()) << status.message();
      ReadbackTargets readback;
      for (uint32_t i = 0; i < kReadbackImageCount; ++i) readback.buffers[i] = slot.readback[i].buffer;
      status = record_world_and_water(cmd, index, *world_, *renderer_, view, time, readback,
                                      &slot.targets);
      EXPECT_TRUE(status.ok()) << status.message();
      EXPECT_TRUE(context_->end_slot_and_submit(index).ok());
      slot.pending = true;
    }
    for (uint32_t frame = std::max(first, end > 2 ? end - 2 : 0); frame < end; ++frame) {
      EXPECT_TRUE(context_->wait_slot(frame % 2).ok());
      collect(slots[frame % 2]);
    }
    return frames;
  }
};

}  // namespace siviflow::testing
