#include "view/screenshot.h"

#include <cmath>
#include <cstdint>
#include <vector>

#include "siviflow/image_files.h"
#include "view/image_barrier.h"

namespace siviflow::view {

Status Screenshot::record_copy(WindowDevice& device, VkCommandBuffer cmd, VkImage image,
                               const ImageState& from, VkExtent2D extent) {
  if (buffer_ == VK_NULL_HANDLE || extent.width != extent_.width || extent.height != extent_.height) {
    destroy();
    device_ = device.device;
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = VkDeviceSize{extent.width} * extent.height * 4;
    info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    VkResult result = vkCreateBuffer(device_, &info, nullptr, &buffer_);
    if (result != VK_SUCCESS) return vk_failure("vkCreateBuffer", result);
    VkMemoryRequirements needs;
    vkGetBufferMemoryRequirements(device_, buffer_, &needs);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = needs.size;
    alloc.memoryTypeIndex = device.memory_type(
        needs.memoryTypeBits,
        VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
    if (alloc.memoryTypeIndex == UINT32_MAX) return Status::error("no host-visible memory for the screenshot");
    result = vkAllocateMemory(device_, &alloc, nullptr, &memory_);
    if (result != VK_SUCCESS) return vk_failure("vkAllocateMemory", result);
    result = vkBindBufferMemory(device_, buffer_, memory_, 0);
    if (result != VK_SUCCESS) return vk_failure("vkBindBufferMemory", result);
    result = vkMapMemory(device_, memory_, 0, VK_WHOLE_SIZE, 0, &mapped_);
    if (result != VK_SUCCESS) return vk_failure("vkMapMemory", result);
    extent_ = extent;
  }
  image_barrier(cmd, image, from, kCopySource);

  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {extent.width, extent.height, 1};
  vkCmdCopyImageToBuffer(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, buffer_, 1, &region);

  VkMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
  to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
  to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
  to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
  to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
  VkDependencyInfo host_dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  host_dependency.memoryBarrierCount = 1;
  host_dependency.pMemoryBarriers = &to_host;
  vkCmdPipelineBarrier2(cmd, &host_dependency);
  return Status::success();
}

Status Screenshot::write_png(const std::string& path, VkFormat format) const {
  if (mapped_ == nullptr) return Status::error("--screenshot: no frame was copied");
  const bool bgra = format == VK_FORMAT_B8G8R8A8_SRGB || format == VK_FORMAT_B8G8R8A8_UNORM;
  const bool srgb = format == VK_FORMAT_B8G8R8A8_SRGB || format == VK_FORMAT_R8G8B8A8_SRGB;
  // The PNG writer takes linear colour and encodes sRGB: decode what the swapchain holds
  // (8-bit sRGB decodes and re-encodes to the same bytes).
  float linear[256];
  for (int v = 0; v < 256; ++v) {
    const float c = static_cast<float>(v) / 255.0f;
    linear[v] = !srgb ? std::pow(c, 2.2f)
                      : (c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f));
  }
  const size_t pixels = size_t{extent_.width} * extent_.height;
  const auto* bytes = static_cast<const uint8_t*>(mapped_);
  std::vector<float> rgba(pixels * 4);
  for (size_t i = 0; i < pixels; ++i) {
    const uint8_t* p = bytes + i * 4;
    rgba[i * 4 + 0] = linear[bgra ? p[2] : p[0]];
    rgba[i * 4 + 1] = linear[p[1]];
    rgba[i * 4 + 2] = linear[bgra ? p[0] : p[2]];
    rgba[i * 4 + 3] = 1.0f;
  }
  return siviflow::write_png(path, static_cast<int>(extent_.width), static_cast<int>(extent_.height),
                             rgba.data(), PngChannels::kRgb);
}

void Screenshot::destroy() {
  if (device_ == VK_NULL_HANDLE) return;
  if (buffer_ != VK_NULL_HANDLE) vkDestroyBuffer(device_, buffer_, nullptr);
  if (memory_ != VK_NULL_HANDLE) vkFreeMemory(device_, memory_, nullptr);
  buffer_ = VK_NULL_HANDLE;
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
  extent_ = {0, 0};
}

}  // namespace siviflow::view
