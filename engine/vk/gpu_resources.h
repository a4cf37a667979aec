// Buffers and images with their own memory. The renderer has a handful of long-lived resources,
// so one dedicated allocation each is simpler than a sub-allocator and costs nothing measurable.
#pragma once

#include <vulkan/vulkan.h>

#include "siviflow/status.h"
#include "vk/access.h"
#include "vk/device_table.h"

namespace siviflow {

struct GpuContext {
  const DeviceTable* table = nullptr;
  const VkAllocationCallbacks* allocation_callbacks = nullptr;
  VkPhysicalDeviceMemoryProperties memory_properties{};
};

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
  void* mapped = nullptr;  // persistently mapped when created host-visible
  bool host_cached = false;  // mapped memory the host reads as fast as its own
};

struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;  // none for images only copied to and from
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkExtent2D extent{0, 0};
};

GpuContext make_gpu_context(const DeviceTable& table, const VkAllocationCallbacks* callbacks);

// host_visible: the memory is HOST_VISIBLE|HOST_COHERENT and mapped for the buffer's lifetime.
Status create_buffer(const GpuContext& gpu, VkDeviceSize size, VkBufferUsageFlags usage,
                     bool host_visible, const char* debug_name, Buffer* out);
// A device-local buffer, also mapped where the device's memory is the host's (every heap
// device-local, one type also HOST_VISIBLE|HOST_COHERENT: lavapipe, integrated GPUs), so that
// the host can fill it in place; elsewhere `mapped` stays null and it is filled by a copy.
Status create_device_buffer(const GpuContext& gpu, VkDeviceSize size, VkBufferUsageFlags usage,
                            const char* debug_name, Buffer* out);
void destroy_buffer(const GpuContext& gpu, Buffer* buffer);

Status create_image(const GpuContext& gpu, VkFormat format, VkExtent2D extent,
                    VkImageUsageFlags usage, const char* debug_name, Image* out,
                    uint32_t mip_levels = 1);
void destroy_image(const GpuContext& gpu, Image* image);

}  // namespace siviflow
