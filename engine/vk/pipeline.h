// Graphics pipelines for dynamic rendering and compute pipelines, built from the SPIR-V embedded
// at build time, and the small objects every pass creates with them: layouts, samplers,
// descriptor sets.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <vulkan/vulkan.h>

#include "siviflow/status.h"
#include "vk/gpu_resources.h"

namespace siviflow {

struct GraphicsPipelineDesc {
  std::string_view vertex_shader;    // embedded module name, e.g. "scene.vert"
  std::string_view fragment_shader;  // e.g. "scene.frag"
  // The fragment shader's specialization constants: constant_id i takes fragment_constants[i]
  // (32 bits each; a bool is 0 or 1). Variants that would otherwise be uniform branches, which a software
  // rasterizer pays for even when untaken.
  std::vector<uint32_t> fragment_constants;
  std::vector<uint32_t> vertex_constants;  // the vertex shader's, laid out alike
  std::vector<VkVertexInputBindingDescription> bindings;
  std::vector<VkVertexInputAttributeDescription> attributes;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  VkFormat color_format = VK_FORMAT_UNDEFINED;  // colour attachment 0; UNDEFINED: depth only
  // Attachments 1.. (motion, reactive, AOVs): never blended.
  std::vector<VkFormat> extra_color_formats;
  VkFormat depth_format = VK_FORMAT_UNDEFINED;  // UNDEFINED: no depth attachment
  bool depth_test = true;
  bool depth_write = true;
  VkCompareOp depth_compare = VK_COMPARE_OP_LESS;
  bool dynamic_depth_compare = false;  // set per draw (vkCmdSetDepthCompareOp): reverse-Z hosts
  VkCullModeFlags cull_mode = VK_CULL_MODE_NONE;
  VkFrontFace front_face = VK_FRONT_FACE_COUNTER_CLOCKWISE;
  // Both set per draw (vkCmdSetCullMode, vkCmdSetFrontFace): one-sided and two-sided meshes,
  // and mirrored views, share the pipeline.
  bool dynamic_culling = false;
  bool alpha_blend = false;  // attachment 0: premultiplied-free "over" blending
};

Status create_graphics_pipeline(const GpuContext& gpu, VkPipelineCache cache,
                                const GraphicsPipelineDesc& desc, VkPipeline* out);

Status create_compute_pipeline(const GpuContext& gpu, VkPipelineCache cache,
                               std::string_view shader, VkPipelineLayout layout, VkPipeline* out);

// The result of a Vulkan call as a Status naming the call: "vkCreateSampler failed: ...".
Status vk_status(VkResult result, const char* call);

// A set layout of `sampler_count` combined image samplers (bindings 0..n-1, fragment stage) and
// a pipeline layout with that set and one push-constant range for the vertex and fragment stages.
Status create_pass_layout(const GpuContext& gpu, uint32_t sampler_count, uint32_t push_constant_bytes,
                          VkDescriptorSetLayout* set_layout, VkPipelineLayout* layout);

// A set layout of `bindings` (binding i of type bindings[i]) for `stages`, and a pipeline layout
// with that set and one push-constant range for `stages`.
Status create_layouts(const GpuContext& gpu, std::span<const VkDescriptorType> bindings,
                      VkShaderStageFlags stages, uint32_t push_constant_bytes,
                      VkDescriptorSetLayout* set_layout, VkPipelineLayout* layout);

// `set_count` sets of that layout from a pool of their own (destroy the pool to free them).
Status allocate_sets(const GpuContext& gpu, VkDescriptorSetLayout set_layout,
                     std::span<const VkDescriptorType> bindings, uint32_t set_count,
                     VkDescriptorPool* pool, VkDescriptorSet* sets);
Status allocate_sampler_sets(const GpuContext& gpu, VkDescriptorSetLayout set_layout,
                             uint32_t sampler_count, uint32_t set_count, VkDescriptorPool* pool,
                             VkDescriptorSet* sets);

Status create_sampler(const GpuContext& gpu, VkFilter filter, VkSamplerAddressMode address,
                      bool mipmapped, VkSampler* out);

// Viewport and scissor covering `extent` (the passes' pipelines keep both dynamic).
void set_viewport(const DeviceTable& vk, VkCommandBuffer cmd, VkExtent2D extent);
void set_viewport(const DeviceTable& vk, VkCommandBuffer cmd, VkRect2D area);

}  // namespace siviflow
