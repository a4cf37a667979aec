// The Access table: every way a frame-graph pass may use an image or a buffer, each mapped to
// exactly one synchronization-2 row {stage, access, layout} and the usage flags it needs.
// Passes never spell stages, access masks or layouts by hand; they pick a row (through a verb of
// the frame graph), so every barrier the graph derives comes from this one table.
//
// Pure data: no device, no calls into Vulkan. Safe to use from any thread.
#pragma once

#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>
#include <string>

namespace siviflow {

enum class Access : uint8_t {
  None,                  // not accessed: the state of fresh memory, or "the host needs no sync"
  TransferRead,          // copy source (vkCmdCopy*, blit)
  TransferWrite,         // copy/clear/fill destination
  ColorAttachmentWrite,  // dynamic-rendering colour attachment (load, blend and store)
  DepthAttachmentWrite,  // depth attachment with depth writes on
  DepthAttachmentRead,   // depth attachment, test only (read-only layout)
  SampledVertex,         // sampled image read in the vertex shader
  SampledFragment,       // sampled image read in the fragment shader
  SampledCompute,        // sampled image read in a compute shader
  StorageReadGraphics,   // storage image/buffer read in vertex or fragment shaders
  StorageReadCompute,    // storage image/buffer read in a compute shader
  StorageWriteCompute,   // storage image/buffer written (and possibly read) in a compute shader
  VertexBufferRead,      // vertex attributes
  IndexBufferRead,       // index buffer
  UniformRead,           // uniform buffer in any shader stage
  HostRead,              // host reads mapped memory (outgoing state of a readback buffer)
  HostWrite,             // host wrote mapped memory (incoming state of a staging buffer)
};
inline constexpr std::size_t kAccessCount = static_cast<std::size_t>(Access::HostWrite) + 1;

// A synchronization state: what last touched a resource (incoming) or what will touch it next
// (outgoing). The layout is ignored for buffers.
struct ResourceState {
  VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
  VkAccessFlags2 access = VK_ACCESS_2_NONE;
  VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;

  bool operator==(const ResourceState&) const = default;
};

// One row of the table.
struct AccessInfo {
  Access id;
  const char* name;  // stable, for dumps and error messages, e.g. "SampledFragment"
  VkPipelineStageFlags2 stage;
  VkAccessFlags2 access;
  VkImageLayout layout;  // UNDEFINED for buffer-only rows
  VkImageUsageFlags image_usage;
  VkBufferUsageFlags buffer_usage;
};

const AccessInfo& access_info(Access access);
inline const char* access_name(Access access) { return access_info(access).name; }
// The row as a state, e.g. to state an import: state_of(Access::HostRead).
ResourceState state_of(Access access);

// The layout a row uses on an image of `format`. Sampled rows on depth/stencil formats use
// DEPTH_STENCIL_READ_ONLY_OPTIMAL, so one pass can sample an image and depth-test against it.
VkImageLayout image_layout(Access access, VkFormat format);

// The write bits of a mask (a barrier after them must make memory available).
VkAccessFlags2 write_bits(VkAccessFlags2 access);
inline bool has_write_access(VkAccessFlags2 access) { return write_bits(access) != 0; }
inline bool is_write(Access access) { return has_write_access(access_info(access).access); }

// The aspects an image view or barrier of this format covers (depth, stencil or colour).
VkImageAspectFlags aspect_of(VkFormat format);

// Stable names for dumps: "EARLY_FRAGMENT_TESTS|LATE_FRAGMENT_TESTS", "TRANSFER_WRITE",
// "NONE" for zero, unknown bits as hex. Layout names drop the VK_IMAGE_LAYOUT_ prefix.
// Messages use vk_text.h's full names instead.
std::string stage_flags_name(VkPipelineStageFlags2 stages);
std::string access_flags_name(VkAccessFlags2 access);
std::string layout_name(VkImageLayout layout);

}  // namespace siviflow
