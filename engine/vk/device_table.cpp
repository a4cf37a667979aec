#include "vk/device_table.h"

namespace siviflow {

VkResult load_device_table(VkInstance instance, VkPhysicalDevice physical_device, VkDevice device,
                           PFN_vkGetInstanceProcAddr get_instance_proc_addr,
                           PFN_vkGetDeviceProcAddr get_device_proc_addr, bool debug_utils,
                           DeviceTable* table, const char** missing) {
  *table = DeviceTable{};
  table->instance = instance;
  table->physical_device = physical_device;
  table->device = device;
  if (get_instance_proc_addr == nullptr) {
    *missing = "vkGetInstanceProcAddr";
    return VK_ERROR_INITIALIZATION_FAILED;
  }
#define SIVIFLOW_LOAD_INSTANCE(name)                                                        \
  table->name = reinterpret_cast<PFN_##name>(get_instance_proc_addr(instance, #name));     \
  if (table->name == nullptr) {                                                             \
    *missing = #name;                                                                       \
    return VK_ERROR_INITIALIZATION_FAILED;                                                  \
  }
  SIVIFLOW_INSTANCE_FUNCTIONS(SIVIFLOW_LOAD_INSTANCE)
#undef SIVIFLOW_LOAD_INSTANCE
  // The host may pass its own vkGetDeviceProcAddr (a layer or a custom loader); prefer it.
  PFN_vkGetDeviceProcAddr device_proc =
      get_device_proc_addr != nullptr ? get_device_proc_addr : table->vkGetDeviceProcAddr;
#define SIVIFLOW_LOAD_DEVICE(name)                                              \
  table->name = reinterpret_cast<PFN_##name>(device_proc(device, #name));       \
  if (table->name == nullptr) {                                                 \
    *missing = #name;                                                           \
    return VK_ERROR_INITIALIZATION_FAILED;                                      \
  }
  SIVIFLOW_DEVICE_FUNCTIONS(SIVIFLOW_LOAD_DEVICE)
#undef SIVIFLOW_LOAD_DEVICE
#define SIVIFLOW_LOAD_OPTIONAL(name) \
  table->name = reinterpret_cast<PFN_##name>(device_proc(device, #name));
  if (debug_utils) {
    SIVIFLOW_DEBUG_LABEL_FUNCTIONS(SIVIFLOW_LOAD_OPTIONAL)
  }
#undef SIVIFLOW_LOAD_OPTIONAL
  *missing = nullptr;
  return VK_SUCCESS;
}

const char* result_name(VkResult result) {
  switch (result) {
#define SIVIFLOW_RESULT_CASE(r) \
  case r:                       \
    return #r;
    SIVIFLOW_RESULT_CASE(VK_SUCCESS)
    SIVIFLOW_RESULT_CASE(VK_NOT_READY)
    SIVIFLOW_RESULT_CASE(VK_TIMEOUT)
    SIVIFLOW_RESULT_CASE(VK_INCOMPLETE)
    SIVIFLOW_RESULT_CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
    SIVIFLOW_RESULT_CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    SIVIFLOW_RESULT_CASE(VK_ERROR_INITIALIZATION_FAILED)
    SIVIFLOW_RESULT_CASE(VK_ERROR_DEVICE_LOST)
    SIVIFLOW_RESULT_CASE(VK_ERROR_MEMORY_MAP_FAILED)
    SIVIFLOW_RESULT_CASE(VK_ERROR_LAYER_NOT_PRESENT)
    SIVIFLOW_RESULT_CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
    SIVIFLOW_RESULT_CASE(VK_ERROR_FEATURE_NOT_PRESENT)
    SIVIFLOW_RESULT_CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
    SIVIFLOW_RESULT_CASE(VK_ERROR_TOO_MANY_OBJECTS)
    SIVIFLOW_RESULT_CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
    SIVIFLOW_RESULT_CASE(VK_ERROR_UNKNOWN)
    SIVIFLOW_RESULT_CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
#undef SIVIFLOW_RESULT_CASE
    default:
      return "VkResult(unknown)";
  }
}

}  // namespace siviflow
