// A host's vkGetDeviceProcAddr, for the renderer's private table, that watches the calls which
// create what holds memory (device memory, buffers, images and their views, samplers, shader
// modules, pipelines and their layouts, descriptor set layouts, pools and sets): it counts them,
// keeps how many of each kind are alive, and can make the k-th of them fail with
// VK_ERROR_OUT_OF_DEVICE_MEMORY. Give device_call_faults::get_device_proc_addr as
// CreateInfo::get_device_proc_addr after install(); the state is per process.
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <string>

#include <vulkan/vulkan.h>

namespace siviflow::testing::device_call_faults {

enum Kind : int {
  kMemory,
  kBuffer,
  kImage,
  kImageView,
  kSampler,
  kShaderModule,
  kPipelineLayout,
  kPipeline,
  kSetLayout,
  kDescriptorPool,
  kDescriptorSets,  // allocations of sets (freed with their pool: not counted alive)
  kKindCount
};

struct State {
  std::array<uint64_t, kKindCount> created{};  // successful calls of each kind
  std::array<int64_t, kKindCount> alive{};     // created minus destroyed
  uint64_t calls = 0;                          // watched calls made, failed ones included
  uint64_t allocated_bytes = 0;                // device memory allocated (frees not subtracted)
  int64_t fail_at = -1;  // the watched call with this index (from 0) fails; negative: none
  std::string failed_call;  // the name of the call made to fail, once it has
};
inline State state;

// Whether the call named `name` is the one to fail.
inline bool inject(const char* name) {
  const bool fail = state.fail_at >= 0 && state.calls == static_cast<uint64_t>(state.fail_at);
  ++state.calls;
  if (fail) state.failed_call = name;
  return fail;
}

inline PFN_vkGetDeviceProcAddr real_get_device_proc_addr = nullptr;
#define SIVIFLOW_REAL(fn) inline PFN_##fn real_##fn = nullptr;
SIVIFLOW_REAL(vkAllocateMemory)
SIVIFLOW_REAL(vkFreeMemory)
SIVIFLOW_REAL(vkCreateBuffer)
SIVIFLOW_REAL(vkDestroyBuffer)
SIVIFLOW_REAL(vkCreateImage)
SIVIFLOW_REAL(vkDestroyImage)
SIVIFLOW_REAL(vkCreateImageView)
SIVIFLOW_REAL(vkDestroyImageView)
SIVIFLOW_REAL(vkCreateSampler)
SIVIFLOW_REAL(vkDestroySampler)
SIVIFLOW_REAL(vkCreateShaderModule)
SIVIFLOW_REAL(vkDestroyShaderModule)
SIVIFLOW_REAL(vkCreatePipelineLayout)
SIVIFLOW_REAL(vkDestroyPipelineLayout)
SIVIFLOW_REAL(vkCreateGraphicsPipelines)
SIVIFLOW_REAL(vkCreateComputePipelines)
SIVIFLOW_REAL(vkDestroyPipeline)
SIVIFLOW_REAL(vkCreateDescriptorSetLayout)
SIVIFLOW_REAL(vkDestroyDescriptorSetLayout)
SIVIFLOW_REAL(vkCreateDescriptorPool)
SIVIFLOW_REAL(vkDestroyDescriptorPool)
SIVIFLOW_REAL(vkAllocateDescriptorSets)
#undef SIVIFLOW_REAL

inline constexpr char kAllocateMemory[] = "vkAllocateMemory";
inline constexpr char kCreateBuffer[] = "vkCreateBuffer";
inline constexpr char kCreateImage[] = "vkCreateImage";
inline constexpr char kCreateImageView[] = "vkCreateImageView";
inline constexpr char kCreateSampler[] = "vkCreateSampler";
inline constexpr char kCreateShaderModule[] = "vkCreateShaderModule";
inline constexpr char kCreatePipelineLayout[] = "vkCreatePipelineLayout";
inline constexpr char kCreateDescriptorSetLayout[] = "vkCreateDescriptorSetLayout";
inline constexpr char kCreateDescriptorPool[] = "vkCreateDescriptorPool";

// vkCreateX(device, info, callbacks, handle) and vkDestroyX(device, handle, callbacks).
template <typename Info, typename Handle, auto& Real, Kind K, const char* Name>
VKAPI_ATTR VkResult VKAPI_CALL create(VkDevice device, const Info* info,
                                      const VkAllocationCallbacks* callbacks, Handle* handle) {
  if (inject(Name)) return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  const VkResult result = Real(device, info, callbacks, handle);
  if (result == VK_SUCCESS) {
    ++state.created[K];
    ++state.alive[K];
    if constexpr (K == kMemory) state.allocated_bytes += info->allocationSize;
  }
  return result;
}
template <typename Handle, auto& Real, Kind K>
VKAPI_ATTR void VKAPI_CALL destroy(VkDevice device, Handle handle,
                                   const VkAllocationCallbacks* callbacks) {
  if (handle != VK_NULL_HANDLE) --state.alive[K];
  Real(device, handle, callbacks);
}

template <typename Info, auto& Real, const char* Name>
VKAPI_ATTR VkResult VKAPI_CALL create_pipelines(VkDevice device, VkPipelineCache cache,
                                                uint32_t count, const Info* infos,
                                                const VkAllocationCallbacks* callbacks,
                                                VkPipeline* pipelines) {
  if (inject(Name)) {
    for (uint32_t i = 0; i < count; ++i) pipelines[i] = VK_NULL_HANDLE;
    return VK_ERROR_OUT_OF_DEVICE_MEMORY;
  }
  const VkResult result = Real(device, cache, count, infos, callbacks, pipelines);
  for (uint32_t i = 0; i < count; ++i) {
    if (pipelines[i] == VK_NULL_HANDLE) continue;
    ++state.created[kPipeline];
    ++state.alive[kPipeline];
  }
  return result;
}
inline constexpr char kCreateGraphicsPipelines[] = "vkCreateGraphicsPipelines";
inline constexpr char kCreateComputePipelines[] = "vkCreateComputePipelines";

inline VKAPI_ATTR VkResult VKAPI_CALL allocate_descriptor_sets(
    VkDevice device, const VkDescriptorSetAllocateInfo* info, VkDescriptorSet* sets) {
  if (inject("vkAllocateDescriptorSets")) return VK_ERROR_OUT_OF_POOL_MEMORY;
  const VkResult result = real_vkAllocateDescriptorSets(device, info, sets);
  if (result == VK_SUCCESS) ++state.created[kDescriptorSets];
  return result;
}

struct Entry {
  const char* name;
  PFN_vkVoidFunction* real;
  PFN_vkVoidFunction wrapper;
};
template <typename Fn>
Entry entry(const char* name, Fn* real, Fn wrapper) {
  return {name, reinterpret_cast<PFN_vkVoidFunction*>(real),
          reinterpret_cast<PFN_vkVoidFunction>(wrapper)};
}

// Returns the watching wrapper of a watched call, the real function of any other.
inline VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL get_device_proc_addr(VkDevice device,
                                                                     const char* name) {
  const PFN_vkVoidFunction real = real_get_device_proc_addr(device, name);
  if (real == nullptr) return nullptr;
  static const Entry entries[] = {
      entry("vkAllocateMemory", &real_vkAllocateMemory,
            &create<VkMemoryAllocateInfo, VkDeviceMemory, real_vkAllocateMemory, kMemory,
                    kAllocateMemory>),
      entry("vkFreeMemory", &real_vkFreeMemory, &destroy<VkDeviceMemory, real_vkFreeMemory, kMemory>),
      entry("vkCreateBuffer", &real_vkCreateBuffer,
            &create<VkBufferCreateInfo, VkBuffer, real_vkCreateBuffer, kBuffer, kCreateBuffer>),
      entry("vkDestroyBuffer", &real_vkDestroyBuffer, &destroy<VkBuffer, real_vkDestroyBuffer, kBuffer>),
      entry("vkCreateImage", &real_vkCreateImage,
            &create<VkImageCreateInfo, VkImage, real_vkCreateImage, kImage, kCreateImage>),
      entry("vkDestroyImage", &real_vkDestroyImage, &destroy<VkImage, real_vkDestroyImage, kImage>),
      entry("vkCreateImageView", &real_vkCreateImageView,
            &create<VkImageViewCreateInfo, VkImageView, real_vkCreateImageView, kImageView,
                    kCreateImageView>),
      entry("vkDestroyImageView", &real_vkDestroyImageView,
            &destroy<VkImageView, real_vkDestroyImageView, kImageView>),
      entry("vkCreateSampler", &real_vkCreateSampler,
            &create<VkSamplerCreateInfo, VkSampler, real_vkCreateSampler, kSampler, kCreateSampler>),
      entry("vkDestroySampler", &real_vkDestroySampler,
            &destroy<VkSampler, real_vkDestroySampler, kSampler>),
      entry("vkCreateShaderModule", &real_vkCreateShaderModule,
            &create<VkShaderModuleCreateInfo, VkShaderModule, real_vkCreateShaderModule,
                    kShaderModule, kCreateShaderModule>),
      entry("vkDestroyShaderModule", &real_vkDestroyShaderModule,
            &destroy<VkShaderModule, real_vkDestroyShaderModule, kShaderModule>),
      entry("vkCreatePipelineLayout", &real_vkCreatePipelineLayout,
            &create<VkPipelineLayoutCreateInfo, VkPipelineLayout, real_vkCreatePipelineLayout,
                    kPipelineLayout, kCreatePipelineLayout>),
      entry("vkDestroyPipelineLayout", &real_vkDestroyPipelineLayout,
            &destroy<VkPipelineLayout, real_vkDestroyPipelineLayout, kPipelineLayout>),
      entry("vkCreateGraphicsPipelines", &real_vkCreateGraphicsPipelines,
            &create_pipelines<VkGraphicsPipelineCreateInfo, real_vkCreateGraphicsPipelines,
                              kCreateGraphicsPipelines>),
      entry("vkCreateComputePipelines", &real_vkCreateComputePipelines,
            &create_pipelines<VkComputePipelineCreateInfo, real_vkCreateComputePipelines,
                              kCreateComputePipelines>),
      entry("vkDestroyPipeline", &real_vkDestroyPipeline,
            &destroy<VkPipeline, real_vkDestroyPipeline, kPipeline>),
      entry("vkCreateDescriptorSetLayout", &real_vkCreateDescriptorSetLayout,
            &create<VkDescriptorSetLayoutCreateInfo, VkDescriptorSetLayout,
                    real_vkCreateDescriptorSetLayout, kSetLayout, kCreateDescriptorSetLayout>),
      entry("vkDestroyDescriptorSetLayout", &real_vkDestroyDescriptorSetLayout,
            &destroy<VkDescriptorSetLayout, real_vkDestroyDescriptorSetLayout, kSetLayout>),
      entry("vkCreateDescriptorPool", &real_vkCreateDescriptorPool,
            &create<VkDescriptorPoolCreateInfo, VkDescriptorPool, real_vkCreateDescriptorPool,
                    kDescriptorPool, kCreateDescriptorPool>),
      entry("vkDestroyDescriptorPool", &real_vkDestroyDescriptorPool,
            &destroy<VkDescriptorPool, real_vkDestroyDescriptorPool, kDescriptorPool>),
      entry("vkAllocateDescriptorSets", &real_vkAllocateDescriptorSets, &allocate_descriptor_sets),
  };
  for (const Entry& e : entries) {
    if (std::strcmp(name, e.name) != 0) continue;
    *e.real = real;
    return e.wrapper;
  }
  return real;
}

// Watches the calls made through get_device_proc_addr from now on; `real` is the host's own.
inline void install(PFN_vkGetDeviceProcAddr real) {
  real_get_device_proc_addr = real;
  state = {};
}

inline uint64_t total(const std::array<uint64_t, kKindCount>& counts) {
  uint64_t sum = 0;
  for (uint64_t n : counts) sum += n;
  return sum;
}

}  // namespace siviflow::testing::device_call_faults
