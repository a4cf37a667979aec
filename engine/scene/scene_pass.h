// The built-in world's pass: sky, terrain, riverbed and objects (siviflow/world.h), drawn into
// the host's colour and depth, and mirrored into the water's reflection.
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "shared.h"
#include "siviflow/status.h"
#include "vk/device_table.h"
#include "vk/frame_graph.h"
#include "vk/gpu_resources.h"

namespace siviflow {

// One indexed draw of the scene pipeline with its own push constants.
struct SceneDraw {
  uint32_t first_index = 0;
  uint32_t index_count = 0;
  const gpu::SceneConstants* constants = nullptr;  // read when the pass records
  // 0: terrain material (vertex colours and the ground detail); k > 0: object material with
  // base-colour texture k - 1 of ScenePass::set_textures.
  uint32_t material = 0;
  // Seen only from outside (the terrain): its back faces are culled.
  bool one_sided = false;
};

class ScenePass {
 public:
  Status create(const GpuContext& gpu, VkPipelineCache cache, VkFormat color_format,
                VkFormat depth_format);
  void destroy(const GpuContext& gpu);
  // Points the pass's descriptors at the ground-detail texture and the objects' base-colour
  // textures (once, after they are created).
  Status set_textures(const GpuContext& gpu, VkImageView detail,
                      const std::vector<VkImageView>& base_colors);

  struct Handles {
    ImageHandle color;
    ImageHandle depth;
    BufferHandle vertices;
    BufferHandle indices;
    ImageHandle detail;
    std::vector<ImageHandle> base_colors;  // in the order of set_textures
  };
  // The view a declared pass draws: its depth convention (the clear value is the caller's) and
  // its viewport.
  struct Frame {
    bool reverse_z = false;
    // One-sided draws' back faces are culled (the main view); outside_lands_clockwise of the
    // view (view_math.h) says which faces those are.
    bool cull_back_faces = false;
    bool outside_clockwise = false;
    VkRect2D viewport{};
    const gpu::SceneConstants* sky = nullptr;  // the view's own constants
  };
  // What each execute binds: the frame's draws and view.
  struct FrameData {
    DataHandle<std::vector<SceneDraw>> draws;
    DataHandle<Frame> view;
  };
  // Declares a pass clearing colour and depth, then drawing the frame's draws and the sky; the
  // new versions of colour and depth go back into `handles`.
  FrameData declare(FrameGraph& graph, const char* pass_name, Handles* handles);
  // Records `draws` then the sky (with `sky`, the view's own constants) into the rendering begun
  // by the caller (viewport set). `view` says the depth convention and the culling.
  void draw(const DeviceTable& vk, VkCommandBuffer cmd, VkBuffer vertices, VkBuffer indices,
            const std::vector<SceneDraw>& draws, const gpu::SceneConstants& sky,
            const Frame& view) const;

 private:
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  std::vector<VkDescriptorSet> sets_;  // per material: the detail texture, then base colours
  VkSampler detail_sampler_ = VK_NULL_HANDLE;
  VkSampler base_color_sampler_ = VK_NULL_HANDLE;
  VkPipeline sky_pipeline_ = VK_NULL_HANDLE;
  VkPipeline scene_pipeline_ = VK_NULL_HANDLE;
  VkPipeline object_pipeline_ = VK_NULL_HANDLE;
};

}  // namespace siviflow
