#include "vk/gpu_resources.h"

#include <string>

namespace siviflow {
namespace {

Status vk_failure(const char* call, const char* name, VkResult result) {
  return Status::error(std::string(call) + " for '" + name + "' failed: " + result_name(result),
                       result);
}

bool find_memory_type(const VkPhysicalDeviceMemoryProperties& props, uint32_t type_bits,
                      VkMemoryPropertyFlags wanted, uint32_t* index) {
  for (uint32_t i = 0; i < props.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) != 0 && (props.memoryTypes[i].propertyFlags & wanted) == wanted) {
      *index = i;
      return true;
    }
  }
  return false;
}

void set_name(const GpuContext& gpu, VkObjectType type, uint64_t handle, const char* name) {
  if (gpu.table->vkSetDebugUtilsObjectNameEXT == nullptr) return;
  VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name;
  gpu.table->vkSetDebugUtilsObjectNameEXT(gpu.table->device, &info);
}

Status allocate(const GpuContext& gpu, const VkMemoryRequirements& requirements,
                VkMemoryPropertyFlags wanted, const char* name, VkDeviceMemory* memory,
                VkMemoryPropertyFlags* type_flags = nullptr) {
  uint32_t type_index = 0;
  if (!find_memory_type(gpu.memory_properties, requirements.memoryTypeBits, wanted, &type_index)) {
    return Status::error(std::string("no suitable memory type for '") + name + "'",
                         VK_ERROR_OUT_OF_DEVICE_MEMORY);
  }
  if (type_flags != nullptr) {
    *type_flags = gpu.memory_properties.memoryTypes[type_index].propertyFlags;
  }
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  info.allocationSize = requirements.size;
  info.memoryTypeIndex = type_index;
  const VkResult result =
      gpu.table->vkAllocateMemory(gpu.table->device, &info, gpu.allocation_callbacks, memory);
  if (result != VK_SUCCESS) return vk_failure("vkAllocateMemory", name, result);
  return Status::success();
}

}  // namespace

GpuContext make_gpu_context(const DeviceTable& table, const VkAllocationCallbacks* callbacks) {
  GpuContext gpu;
  gpu.table = &table;
  gpu.allocation_callbacks = callbacks;
  table.vkGetPhysicalDeviceMemoryProperties(table.physical_device, &gpu.memory_properties);
  return gpu;
}

namespace {

enum class BufferMemory { kDeviceLocal, kHostVisible, kMappedIfUnified };

// Whether the device's memory is the host's: no heap apart from device-local ones.
bool unified_memory(const VkPhysicalDeviceMemoryProperties& props) {
  for (uint32_t i = 0; i < props.memoryHeapCount; ++i) {
    if ((props.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) == 0) return false;
  }
  return true;
}

Status make_buffer(const GpuContext& gpu, VkDeviceSize size, VkBufferUsageFlags usage,
                   BufferMemory memory, const char* debug_name, Buffer* out) {
  const DeviceTable& vk = *gpu.table;
  *out = Buffer{};
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkResult result = vk.vkCreateBuffer(vk.device, &info, gpu.allocation_callbacks, &out->buffer);
  if (result != VK_SUCCESS) return vk_failure("vkCreateBuffer", debug_name, result);
  out->size = size;
  VkMemoryRequirements requirements;
  vk.vkGetBufferMemoryRequirements(vk.device, out->buffer, &requirements);
  constexpr VkMemoryPropertyFlags kHost =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VkMemoryPropertyFlags wanted = memory == BufferMemory::kHostVisible
                                     ? kHost
                                     : VkMemoryPropertyFlags{VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT};
  if (memory == BufferMemory::kMappedIfUnified && unified_memory(gpu.memory_properties)) {
    // Cached where the device offers it: the host then reads it as fast as its own.
    uint32_t shared_type = 0;
    for (const VkMemoryPropertyFlags shared :
         {wanted | kHost | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, wanted | kHost}) {
      if (find_memory_type(gpu.memory_properties, requirements.memoryTypeBits, shared,
                           &shared_type)) {
        wanted = shared;
        break;
      }
    }
  }
  VkMemoryPropertyFlags type_flags = 0;
  Status status = allocate(gpu, requirements, wanted, debug_name, &out->memory, &type_flags);
  if (status.ok()) {
    result = vk.vkBindBufferMemory(vk.device, out->buffer, out->memory, 0);
    if (result != VK_SUCCESS) status = vk_failure("vkBindBufferMemory", debug_name, result);
  }
  if (status.ok() && (wanted & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) != 0) {
    result = vk.vkMapMemory(vk.device, out->memory, 0, VK_WHOLE_SIZE, 0, &out->mapped);
    if (result != VK_SUCCESS) status = vk_failure("vkMapMemory", debug_name, result);
    out->host_cached = (type_flags & VK_MEMORY_PROPERTY_HOST_CACHED_BIT) != 0;
  }
  if (!status.ok()) {
    destroy_buffer(gpu, out);
    return status;
  }
  set_name(gpu, VK_OBJECT_TYPE_BUFFER, reinterpret_cast<uint64_t>(out->buffer), debug_name);
  return Status::success();
}

}  // namespace

Status create_buffer(const GpuContext& gpu, VkDeviceSize size, VkBufferUsageFlags usage,
                     bool host_visible, const char* debug_name, Buffer* out) {
  return make_buffer(gpu, size, usage,
                     host_visible ? BufferMemory::kHostVisible : BufferMemory::kDeviceLocal,
                     debug_name, out);
}

Status create_device_buffer(const GpuContext& gpu, VkDeviceSize size, VkBufferUsageFlags usage,
                            const char* debug_name, Buffer* out) {
  return make_buffer(gpu, size, usage, BufferMemory::kMappedIfUnified, debug_name, out);
}

void destroy_buffer(const GpuContext& gpu, Buffer* buffer) {
  const DeviceTable& vk = *gpu.table;
  if (buffer->buffer != VK_NULL_HANDLE) {
    vk.vkDestroyBuffer(vk.device, buffer->buffer, gpu.allocation_callbacks);
  }
  if (buffer->memory != VK_NULL_HANDLE) {
    vk.vkFreeMemory(vk.device, buffer->memory, gpu.allocation_callbacks);  // also unmaps
  }
  *buffer = Buffer{};
}

Status create_image(const GpuContext& gpu, VkFormat format, VkExtent2D extent,
                    VkImageUsageFlags usage, const char* debug_name, Image* out,
                    uint32_t mip_levels) {
  const DeviceTable& vk = *gpu.table;
  *out = Image{};
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {extent.width, extent.height, 1};
  info.mipLevels = mip_levels;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkResult result = vk.vkCreateImage(vk.device, &info, gpu.allocation_callbacks, &out->image);
  if (result != VK_SUCCESS) return vk_failure("vkCreateImage", debug_name, result);
  out->format = format;
  out->extent = extent;
  VkMemoryRequirements requirements;
  vk.vkGetImageMemoryRequirements(vk.device, out->image, &requirements);
  Status status =
      allocate(gpu, requirements, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, debug_name, &out->memory);
  if (status.ok()) {
    result = vk.vkBindImageMemory(vk.device, out->image, out->memory, 0);
    if (result != VK_SUCCESS) status = vk_failure("vkBindImageMemory", debug_name, result);
  }
  // Views only for images that shaders or attachments use; copy-only images have none.
  constexpr VkImageUsageFlags kViewUsages =
      VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT |
      VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
      VK_IMAGE_USAGE_INPUT_ATTACHMENT_BIT;
  if (status.ok() && (usage & kViewUsages) != 0) {
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = out->image;
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspect_of(format), 0, mip_levels, 0, 1};
    result = vk.vkCreateImageView(vk.device, &view, gpu.allocation_callbacks, &out->view);
    if (result != VK_SUCCESS) status = vk_failure("vkCreateImageView", debug_name, result);
  }
  if (!status.ok()) {
    destroy_image(gpu, out);
    return status;
  }
  set_name(gpu, VK_OBJECT_TYPE_IMAGE, reinterpret_cast<uint64_t>(out->image), debug_name);
  return Status::success();
}

void destroy_image(const GpuContext& gpu, Image* image) {
  const DeviceTable& vk = *gpu.table;
  if (image->view != VK_NULL_HANDLE) {
    vk.vkDestroyImageView(vk.device, image->view, gpu.allocation_callbacks);
  }
  if (image->image != VK_NULL_HANDLE) {
    vk.vkDestroyImage(vk.device, image->image, gpu.allocation_callbacks);
  }
  if (image->memory != VK_NULL_HANDLE) {
    vk.vkFreeMemory(vk.device, image->memory, gpu.allocation_callbacks);
  }
  *image = Image{};
}

}  // namespace siviflow
