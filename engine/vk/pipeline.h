// Graphics pipelines for dynamic rendering, built from the SPIR-V embedded at build time.
#pragma once

#include <cstdint>
#include <string_view>
#include <vector>

#include <vulkan/vulkan.h>

#include "sim/status.h"
#include "vk/gpu_resources.h"

namespace siviflow {

struct GraphicsPipelineDesc {
  std::string_view vertex_shader;    // embedded module name, e.g. "scene.vert"
  std::string_view fragment_shader;  // e.g. "scene.frag"
  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attributes;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkFormat color_format = VK_FORMAT_UNDEFINED;        // colour attachment 0
  std::vector<VkFormat> extra_color_formats;         // attachments 1.. (AOVs): never blended
  VkFormat depth_format = VK_FORMAT_UNDEFINED;  // UNDEFINED: no depth attachment
  bool depth_test = true;
  bool depth_write = true;
  VkCompareOp depth_compare = VK_COMPARE_OP_LESS;
  VkCullModeFlags cull_mode = VK_CULL_MODE_NONE;
  VkFrontFace front_face = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  bool alpha_blend = false;  // attachment 0: premultiplied-free "over" blending
};

Status create_graphics_pipeline(const GpuContext& gpu, VkPipelineCache cache,
                                const GraphicsPipelineDesc& desc, VkPipeline* out);

}  // namespace siviflow
