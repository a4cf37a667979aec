// The passes of the SiViFlow frame graph. Each pass knows the frame graph and its own shaders,
// not the other passes; the renderer wires their handles together.
#pragma once

#include <cstdint>
#include <vector>

#include <vulkan/vulkan.h>

#include "scene/default_scene.h"
#include "shared.h"
#include "sim/status.h"
#include "vk/frame_graph.h"
#include "vk/frame_ring.h"
#include "vk/gpu_resources.h"

namespace siviflow {

// ---- upload: staging block -> device buffers and images (always a real copy) ----

// One copy from the frame slot's staging block, recorded by the upload pass. Destinations are
// graph handles, so the copy and the graph's barriers always name the same resource.
struct BufferUpload {
  VkDeviceSize staging_offset = 0;
  BufferHandle destination;
  VkDeviceSize size = 0;
};
struct ImageUpload {
  VkDeviceSize staging_offset = 0;
  ImageHandle destination;
  VkExtent2D extent{};
};

// What the upload pass copies; filled on the CPU before the pass records.
struct UploadList {
  std::vector<BufferUpload> buffers;
  std::vector<ImageUpload> images;
  void clear() {
    buffers.clear();
    images.clear();
  }
};

// Declares the pass: it writes every destination of `list` (their handles are replaced by the
// written versions) from the imported staging buffer. `list` is read again when the pass records.
void add_upload_pass(FrameGraph& graph, BufferHandle staging, UploadList* list);

// ---- scene: sky, terrain, riverbed and objects ----

class ScenePass {
 public:
  Status create(const GpuContext& gpu, VkPipelineCache cache, VkFormat color_format,
                VkFormat depth_format);
  void destroy(const GpuContext& gpu);
  // Points the pass's descriptor at the ground-detail texture (once, after it is created).
  void set_detail_texture(const GpuContext& gpu, VkImageView view);

  struct Handles {
    ImageHandle color;
    ImageHandle depth;
    BufferHandle vertices;
    BufferHandle indices;
    ImageHandle detail;
  };
  // Declares the pass; the new versions of colour and depth are written back into `handles`.
  void declare(FrameGraph& graph, const gpu::SceneConstants* constants, uint32_t index_count,
               Handles* handles);

 private:
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
  VkSampler sampler_ = VK_NULL_HANDLE;
  VkPipeline sky_pipeline_ = VK_NULL_HANDLE;
  VkPipeline scene_pipeline_ = VK_NULL_HANDLE;
};

// ---- water mask: 1 where the river surface is the nearest thing on screen ----

class WaterMaskPass {
 public:
  static constexpr VkFormat kFormat = VK_FORMAT_R32_SFLOAT;
  Status create(const GpuContext& gpu, VkPipelineCache cache, VkFormat depth_format);
  void destroy(const GpuContext& gpu);

  struct Handles {
    ImageHandle mask;        // written (cleared to 0, 1 on visible water)
    ImageHandle depth;       // the scene's depth, tested against, not written
    BufferHandle vertices;   // river surface positions (vec3)
    BufferHandle indices;
  };
  void declare(FrameGraph& graph, const gpu::SceneConstants* constants, uint32_t index_count,
               Handles* handles);

 private:
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
};

// ---- readback: images -> host buffers (tools and tests only) ----

struct ReadbackCopy {
  ImageHandle image;    // copied whole, tightly packed (depth formats: the depth aspect)
  BufferHandle buffer;  // imported, handed back in the HostRead state; replaced by the written version
};
void add_readback_pass(FrameGraph& graph, std::vector<ReadbackCopy>* copies);

}  // namespace siviflow
