#include "view/frame_slots.h"

namespace siviflow::view {
namespace {

constexpr VkImageUsageFlags kColorUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                          VK_IMAGE_USAGE_SAMPLED_BIT |
                                          VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
constexpr VkImageUsageFlags kDepthUsage =
    VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;

}  // namespace

Status FrameSlots::create(WindowDevice& device, uint32_t count, VkExtent2D extent) {
  device_ = &device;
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(device.physical_device, &props);
  ns_per_tick_ = props.limits.timestampPeriod;
  slots_.resize(count);
  ticks_.assign(count, std::vector<uint64_t>(kTimestampCount, 0));
  for (FrameSlot& slot : slots_) {
    VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    pool_info.queueFamilyIndex = device.queue_family;
    VkResult result = vkCreateCommandPool(device.device, &pool_info, nullptr, &slot.pool);
    if (result != VK_SUCCESS) return vk_failure("vkCreateCommandPool", result);
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = slot.pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    result = vkAllocateCommandBuffers(device.device, &alloc, &slot.cmd);
    if (result != VK_SUCCESS) return vk_failure("vkAllocateCommandBuffers", result);
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    result = vkCreateFence(device.device, &fence_info, nullptr, &slot.fence);
    if (result != VK_SUCCESS) return vk_failure("vkCreateFence", result);
    VkSemaphoreCreateInfo semaphore_info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    result = vkCreateSemaphore(device.device, &semaphore_info, nullptr, &slot.acquired);
    if (result != VK_SUCCESS) return vk_failure("vkCreateSemaphore", result);
    VkQueryPoolCreateInfo query_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    query_info.queryType = VK_QUERY_TYPE_TIMESTAMP;
    query_info.queryCount = kTimestampCount;
    result = vkCreateQueryPool(device.device, &query_info, nullptr, &slot.timestamps);
    if (result != VK_SUCCESS) return vk_failure("vkCreateQueryPool", result);
    SIVIFLOW_TRY(create_images(&slot, extent));
  }
  return Status::success();
}

Status FrameSlots::create_image(VkFormat format, VkExtent2D extent, VkImageUsageFlags usage,
                                VkImageAspectFlags aspect, ExternalImage* out,
                                VkDeviceMemory* memory) {
  const VkDevice device = device_->device;
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {extent.width, extent.height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkResult result = vkCreateImage(device, &info, nullptr, &out->image);
  if (result != VK_SUCCESS) return vk_failure("vkCreateImage", result);
  VkMemoryRequirements needs;
  vkGetImageMemoryRequirements(device, out->image, &needs);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = needs.size;
  alloc.memoryTypeIndex =
      device_->memory_type(needs.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  if (alloc.memoryTypeIndex == UINT32_MAX) return Status::error("no device-local memory for an image");
  result = vkAllocateMemory(device, &alloc, nullptr, memory);
  if (result != VK_SUCCESS) return vk_failure("vkAllocateMemory", result);
  result = vkBindImageMemory(device, out->image, *memory, 0);
  if (result != VK_SUCCESS) return vk_failure("vkBindImageMemory", result);
  VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view_info.image = out->image;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = format;
  view_info.subresourceRange = {aspect, 0, 1, 0, 1};
  result = vkCreateImageView(device, &view_info, nullptr, &out->view);
  if (result != VK_SUCCESS) return vk_failure("vkCreateImageView", result);
  out->format = format;
  out->extent = extent;
  out->usage = usage;
  out->current = ImageState{};  // undefined: its first frame discards nothing it needs
  return Status::success();
}

Status FrameSlots::create_images(FrameSlot* slot, VkExtent2D extent) {
  SIVIFLOW_TRY(create_image(kFrameColorFormat, extent, kColorUsage, VK_IMAGE_ASPECT_COLOR_BIT,
                            &slot->color, &slot->color_memory));
  SIVIFLOW_TRY(create_image(kFrameDepthFormat, extent, kDepthUsage, VK_IMAGE_ASPECT_DEPTH_BIT,
                            &slot->depth, &slot->depth_memory));
  // The world leaves the colour ready for the water; the water leaves it ready to be copied to
  // the swapchain, and the depth ready to be tested against by the next frame's clear.
  slot->color.final = {VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                       VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  slot->depth.final = {VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                       VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL};
  return Status::success();
}

void FrameSlots::destroy_images(FrameSlot* slot) {
  const VkDevice device = device_->device;
  for (ExternalImage* image : {&slot->color, &slot->depth}) {
    if (image->view != VK_NULL_HANDLE) vkDestroyImageView(device, image->view, nullptr);
    if (image->image != VK_NULL_HANDLE) vkDestroyImage(device, image->image, nullptr);
    *image = ExternalImage{};
  }
  for (VkDeviceMemory* memory : {&slot->color_memory, &slot->depth_memory}) {
    if (*memory != VK_NULL_HANDLE) vkFreeMemory(device, *memory, nullptr);
    *memory = VK_NULL_HANDLE;
  }
}

Status FrameSlots::resize(VkExtent2D extent) {
  for (FrameSlot& slot : slots_) {
    destroy_images(&slot);
    SIVIFLOW_TRY(create_images(&slot, extent));
  }
  return Status::success();
}

void FrameSlots::read_timestamps(uint32_t slot) {
  FrameSlot& s = slots_[slot];
  if (!s.timestamps_written) return;
  vkGetQueryPoolResults(device_->device, s.timestamps, 0, kTimestampCount,
                        sizeof(uint64_t) * kTimestampCount, ticks_[slot].data(), sizeof(uint64_t),
                        VK_QUERY_RESULT_64_BIT);
}

double FrameSlots::gpu_ms(uint32_t slot, FrameTimestamp from, FrameTimestamp to) const {
  const std::vector<uint64_t>& t = ticks_[slot];
  if (t[to] < t[from]) return 0.0;
  return static_cast<double>(t[to] - t[from]) * ns_per_tick_ * 1e-6;
}

void FrameSlots::destroy() {
  if (device_ == nullptr) return;
  const VkDevice device = device_->device;
  for (FrameSlot& slot : slots_) {
    destroy_images(&slot);
    if (slot.timestamps != VK_NULL_HANDLE) vkDestroyQueryPool(device, slot.timestamps, nullptr);
    if (slot.acquired != VK_NULL_HANDLE) vkDestroySemaphore(device, slot.acquired, nullptr);
    if (slot.fence != VK_NULL_HANDLE) vkDestroyFence(device, slot.fence, nullptr);
    if (slot.pool != VK_NULL_HANDLE) vkDestroyCommandPool(device, slot.pool, nullptr);
  }
  slots_.clear();
}

}  // namespace siviflow::view
