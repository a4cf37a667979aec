// A host's vkGetDeviceProcAddr that counts the calls a renderer makes to create what holds
// memory (device memory, buffers, images, descriptor pools and sets), for tests that a long run
// creates none after its warm-up. Give counting_device_procs::get_device_proc_addr as
// CreateInfo::get_device_proc_addr after install(); the counts are per process.
#pragma once

#include <cstdint>
#include <cstring>
#include <type_traits>

#include <vulkan/vulkan.h>

namespace siviflow::testing::counting_device_procs {

struct Counts {
  uint64_t allocate_memory = 0;
  uint64_t create_buffer = 0;
  uint64_t create_image = 0;
  uint64_t create_descriptor_pool = 0;
  uint64_t allocate_descriptor_sets = 0;
  bool operator==(const Counts&) const = default;
};

inline Counts counts;
inline PFN_vkGetDeviceProcAddr real_get_device_proc_addr = nullptr;
inline PFN_vkAllocateMemory real_allocate_memory = nullptr;
inline PFN_vkCreateBuffer real_create_buffer = nullptr;
inline PFN_vkCreateImage real_create_image = nullptr;
inline PFN_vkCreateDescriptorPool real_create_descriptor_pool = nullptr;
inline PFN_vkAllocateDescriptorSets real_allocate_descriptor_sets = nullptr;

inline VKAPI_ATTR VkResult VKAPI_CALL allocate_memory(VkDevice device,
                                                      const VkMemoryAllocateInfo* info,
                                                      const VkAllocationCallbacks* callbacks,
                                                      VkDeviceMemory* memory) {
  ++counts.allocate_memory;
  return real_allocate_memory(device, info, callbacks, memory);
}
inline VKAPI_ATTR VkResult VKAPI_CALL create_buffer(VkDevice device, const VkBufferCreateInfo* info,
                                                    const VkAllocationCallbacks* callbacks,
                                                    VkBuffer* buffer) {
  ++counts.create_buffer;
  return real_create_buffer(device, info, callbacks, buffer);
}
inline VKAPI_ATTR VkResult VKAPI_CALL create_image(VkDevice device, const VkImageCreateInfo* info,
                                                   const VkAllocationCallbacks* callbacks,
                                                   VkImage* image) {
  ++counts.create_image;
  return real_create_image(device, info, callbacks, image);
}
inline VKAPI_ATTR VkResult VKAPI_CALL create_descriptor_pool(
    VkDevice device, const VkDescriptorPoolCreateInfo* info,
    const VkAllocationCallbacks* callbacks, VkDescriptorPool* pool) {
  ++counts.create_descriptor_pool;
  return real_create_descriptor_pool(device, info, callbacks, pool);
}
inline VKAPI_ATTR VkResult VKAPI_CALL allocate_descriptor_sets(
    VkDevice device, const VkDescriptorSetAllocateInfo* info, VkDescriptorSet* sets) {
  ++counts.allocate_descriptor_sets;
  return real_allocate_descriptor_sets(device, info, sets);
}

// Returns the counting wrapper for the counted calls, the real function for the others.
inline VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL get_device_proc_addr(VkDevice device,
                                                                     const char* name) {
  const PFN_vkVoidFunction real = real_get_device_proc_addr(device, name);
  if (real == nullptr) return nullptr;
  const auto wrap = [&](auto* real_slot, auto* wrapper) {
    *real_slot = reinterpret_cast<std::remove_pointer_t<decltype(real_slot)>>(real);
    return reinterpret_cast<PFN_vkVoidFunction>(wrapper);
  };
  if (std::strcmp(name, "vkAllocateMemory") == 0) return wrap(&real_allocate_memory, &allocate_memory);
  if (std::strcmp(name, "vkCreateBuffer") == 0) return wrap(&real_create_buffer, &create_buffer);
  if (std::strcmp(name, "vkCreateImage") == 0) return wrap(&real_create_image, &create_image);
  if (std::strcmp(name, "vkCreateDescriptorPool") == 0) {
    return wrap(&real_create_descriptor_pool, &create_descriptor_pool);
  }
  if (std::strcmp(name, "vkAllocateDescriptorSets") == 0) {
    return wrap(&real_allocate_descriptor_sets, &allocate_descriptor_sets);
  }
  return real;
}

// Counts the calls made through get_device_proc_addr from now on; `real` is the host's own.
inline void install(PFN_vkGetDeviceProcAddr real) {
  real_get_device_proc_addr = real;
  counts = {};
}

}  // namespace siviflow::testing::counting_device_procs
