// Vulkan values by their names, for messages: "VK_FORMAT_B10G11R11_UFLOAT_PACK32" rather than
// "122", so that a message can be read (and searched for in the specification) as it stands.
// Every core value of Vulkan 1.3 (header 1.3.239) is named; a value outside them keeps its number.
//
// Pure data: no device, no calls into Vulkan. Safe to use from any thread.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>

namespace siviflow {

// "VK_FORMAT_R16G16B16A16_SFLOAT"; an unknown value as "VkFormat 123456789".
std::string format_name(VkFormat format);

// Of an uncompressed, single-plane colour format (R8_UNORM 1, B10G11R11_UFLOAT_PACK32 4,
// R32G32B32A32_SFLOAT 16): the bytes of one texel, its channels, whether one is alpha. 0 (false)
// for UNDEFINED, depth/stencil, compressed, multi-planar and unknown formats and those that need
// a sampler YCbCr conversion (G8B8G8R8_422_UNORM, R10X6G10X6B10X6A10X6_UNORM_4PACK16).
uint32_t color_texel_bytes(VkFormat format);
uint32_t color_channel_count(VkFormat format);
bool color_has_alpha(VkFormat format);

// Flags as their bit names in ascending bit order, joined by " | ", the bits with no name as one
// trailing hex number: "VK_IMAGE_USAGE_TRANSFER_SRC_BIT | 0x40000000". Zero is "0", but stages and
// accesses have a name for it: "VK_PIPELINE_STAGE_2_NONE", "VK_ACCESS_2_NONE".
std::string image_usage_text(VkImageUsageFlags usage);
std::string format_feature_text(VkFormatFeatureFlags features);
std::string stage_text(VkPipelineStageFlags2 stages);
std::string access_text(VkAccessFlags2 access);

// "VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL" (and VK_KHR_swapchain's PRESENT_SRC_KHR, which hosts
// present from); an unknown value as "VkImageLayout 123456789".
std::string layout_text(VkImageLayout layout);

}  // namespace siviflow
