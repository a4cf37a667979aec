// Private Vulkan function table. The engine is compiled with VK_NO_PROTOTYPES, so every
// Vulkan call goes through a table loaded from the host's vkGet*ProcAddr: the library works
// with hosts that use volk, a custom loader or extra layers, and never calls global vk* symbols.
#pragma once

#include <vulkan/vulkan.h>

namespace siviflow {

// Instance-level functions the engine needs (queries on the host's physical device, debug labels).
#define SIVIFLOW_INSTANCE_FUNCTIONS(X)         \
  X(vkGetPhysicalDeviceProperties2)            \
  X(vkGetPhysicalDeviceFeatures2)              \
  X(vkGetPhysicalDeviceMemoryProperties)       \
  X(vkGetPhysicalDeviceFormatProperties)       \
  X(vkGetPhysicalDeviceQueueFamilyProperties)  \
  X(vkGetDeviceProcAddr)

// Device-level functions.
#define SIVIFLOW_DEVICE_FUNCTIONS(X)   \
  X(vkAllocateMemory)                  \
  X(vkFreeMemory)                      \
  X(vkMapMemory)                       \
  X(vkCreateBuffer)                    \
  X(vkDestroyBuffer)                   \
  X(vkGetBufferMemoryRequirements)     \
  X(vkBindBufferMemory)                \
  X(vkCreateImage)                     \
  X(vkDestroyImage)                    \
  X(vkGetImageMemoryRequirements)      \
  X(vkBindImageMemory)                 \
  X(vkCreateImageView)                 \
  X(vkDestroyImageView)                \
  X(vkCreateSampler)                   \
  X(vkDestroySampler)                  \
  X(vkCreateShaderModule)              \
  X(vkDestroyShaderModule)             \
  X(vkCreatePipelineLayout)            \
  X(vkDestroyPipelineLayout)           \
  X(vkCreateGraphicsPipelines)         \
  X(vkCreateComputePipelines)          \
  X(vkDestroyPipeline)                 \
  X(vkCreateDescriptorSetLayout)       \
  X(vkDestroyDescriptorSetLayout)      \
  X(vkCreateDescriptorPool)            \
  X(vkDestroyDescriptorPool)           \
  X(vkAllocateDescriptorSets)          \
  X(vkUpdateDescriptorSets)            \
  X(vkCmdPipelineBarrier2)             \
  X(vkCmdBeginRendering)               \
  X(vkCmdEndRendering)                 \
  X(vkCmdBindPipeline)                 \
  X(vkCmdBindDescriptorSets)           \
  X(vkCmdBindVertexBuffers)            \
  X(vkCmdBindIndexBuffer)              \
  X(vkCmdPushConstants)                \
  X(vkCmdSetViewport)                  \
  X(vkCmdSetScissor)                   \
  X(vkCmdSetDepthCompareOp)            \
  X(vkCmdSetCullMode)                  \
  X(vkCmdSetFrontFace)                 \
  X(vkCmdDraw)                         \
  X(vkCmdDispatch)                     \
  X(vkCmdDrawIndexed)                  \
  X(vkCmdCopyBuffer)                   \
  X(vkCmdCopyBufferToImage)            \
  X(vkCmdCopyImage)                    \
  X(vkCmdCopyImageToBuffer)            \
  X(vkCreateQueryPool)                 \
  X(vkDestroyQueryPool)                \
  X(vkCmdResetQueryPool)               \
  X(vkCmdWriteTimestamp2)              \
  X(vkGetQueryPoolResults)

// VK_EXT_debug_utils labels: loaded only when the host says it enabled the extension (a loader
// may hand out entry points of extensions that are not enabled, and calling them crashes).
#define SIVIFLOW_DEBUG_LABEL_FUNCTIONS(X) \
  X(vkCmdBeginDebugUtilsLabelEXT)         \
  X(vkCmdEndDebugUtilsLabelEXT)           \
  X(vkSetDebugUtilsObjectNameEXT)

#define SIVIFLOW_DECLARE_PFN(name) PFN_##name name = nullptr;

struct DeviceTable {
  VkInstance instance = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  SIVIFLOW_INSTANCE_FUNCTIONS(SIVIFLOW_DECLARE_PFN)
  SIVIFLOW_DEVICE_FUNCTIONS(SIVIFLOW_DECLARE_PFN)
  SIVIFLOW_DEBUG_LABEL_FUNCTIONS(SIVIFLOW_DECLARE_PFN)

  bool has_debug_labels() const { return vkCmdBeginDebugUtilsLabelEXT != nullptr; }
};

#undef SIVIFLOW_DECLARE_PFN

// Loads every function of the table. Returns VK_ERROR_INITIALIZATION_FAILED and names the first
// missing function in *missing when a required one cannot be resolved.
VkResult load_device_table(VkInstance instance, VkPhysicalDevice physical_device, VkDevice device,
                           PFN_vkGetInstanceProcAddr get_instance_proc_addr,
                           PFN_vkGetDeviceProcAddr get_device_proc_addr, bool debug_utils,
                           DeviceTable* table, const char** missing);

// Human-readable name of a VkResult, e.g. "VK_ERROR_DEVICE_LOST".
const char* result_name(VkResult result);

}  // namespace siviflow
