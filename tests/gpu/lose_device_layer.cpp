// A Vulkan layer for tests only: it makes the device look lost at a chosen point, as a driver
// reset or a hung GPU would, to see what a host of ours does then. The capture tool opens the
// loader itself (dlopen, RTLD_LOCAL), so a layer is how a test reaches its submits and waits.
//
// SIVIFLOW_TEST_LOSE_DEVICE=submit:N makes the N-th vkQueueSubmit2 return VK_ERROR_DEVICE_LOST
// without submitting; wait:N makes the N-th vkWaitForFences wait and then return it. At that
// point the layer waits for the real device to go idle, so what the host frees afterwards is no
// longer in use, and from then on every submit, fence wait and device wait returns
// VK_ERROR_DEVICE_LOST. One instance and one device per process, as the capture tool makes.
#include <vulkan/vk_layer.h>
#include <vulkan/vulkan.h>

#include <cstdlib>
#include <cstring>
#include <string>

namespace {

struct LayerState {
  PFN_vkGetInstanceProcAddr next_instance_proc = nullptr;
  PFN_vkGetDeviceProcAddr next_device_proc = nullptr;
  PFN_vkQueueSubmit2 next_submit2 = nullptr;
  PFN_vkWaitForFences next_wait_for_fences = nullptr;
  PFN_vkDeviceWaitIdle next_device_wait_idle = nullptr;
  VkDevice device = VK_NULL_HANDLE;
  bool lose_on_submit = false;
  long lose_at = 0;  // 1-based count of the chosen call; 0: never
  long calls = 0;
  bool lost = false;
};
LayerState state;

void read_setting() {
  const char* text = std::getenv("SIVIFLOW_TEST_LOSE_DEVICE");
  if (text == nullptr) return;
  const std::string setting = text;
  const size_t colon = setting.find(':');
  if (colon == std::string::npos) return;
  state.lose_on_submit = setting.compare(0, colon, "submit") == 0;
  state.lose_at = std::strtol(setting.c_str() + colon + 1, nullptr, 10);
}

VkResult lose_device() {
  state.lost = true;
  state.next_device_wait_idle(state.device);
  return VK_ERROR_DEVICE_LOST;
}

VKAPI_ATTR VkResult VKAPI_CALL queue_submit2(VkQueue queue, uint32_t count,
                                             const VkSubmitInfo2* submits, VkFence fence) {
  if (state.lost) return VK_ERROR_DEVICE_LOST;
  if (state.lose_on_submit && ++state.calls == state.lose_at) return lose_device();
  return state.next_submit2(queue, count, submits, fence);
}

VKAPI_ATTR VkResult VKAPI_CALL wait_for_fences(VkDevice device, uint32_t count,
                                               const VkFence* fences, VkBool32 wait_all,
                                               uint64_t timeout) {
  if (state.lost) return VK_ERROR_DEVICE_LOST;
  const VkResult result = state.next_wait_for_fences(device, count, fences, wait_all, timeout);
  if (!state.lose_on_submit && ++state.calls == state.lose_at) return lose_device();
  return result;
}

VKAPI_ATTR VkResult VKAPI_CALL device_wait_idle(VkDevice device) {
  const VkResult result = state.next_device_wait_idle(device);
  return state.lost ? VK_ERROR_DEVICE_LOST : result;
}

template <typename Info>
Info* find_link(const void* next, VkStructureType type) {
  auto* info = static_cast<Info*>(const_cast<void*>(next));
  while (info != nullptr && !(info->sType == type && info->function == VK_LAYER_LINK_INFO)) {
    info = static_cast<Info*>(const_cast<void*>(info->pNext));
  }
  return info;
}

VKAPI_ATTR VkResult VKAPI_CALL create_instance(const VkInstanceCreateInfo* info,
                                               const VkAllocationCallbacks* allocator,
                                               VkInstance* instance) {
  auto* link = find_link<VkLayerInstanceCreateInfo>(info->pNext,
                                                    VK_STRUCTURE_TYPE_LOADER_INSTANCE_CREATE_INFO);
  if (link == nullptr) return VK_ERROR_INITIALIZATION_FAILED;
  state.next_instance_proc = link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  const auto next_create = reinterpret_cast<PFN_vkCreateInstance>(
      state.next_instance_proc(VK_NULL_HANDLE, "vkCreateInstance"));
  read_setting();
  return next_create(info, allocator, instance);
}

VKAPI_ATTR VkResult VKAPI_CALL create_device(VkPhysicalDevice physical_device,
                                             const VkDeviceCreateInfo* info,
                                             const VkAllocationCallbacks* allocator,
                                             VkDevice* device) {
  auto* link =
      find_link<VkLayerDeviceCreateInfo>(info->pNext, VK_STRUCTURE_TYPE_LOADER_DEVICE_CREATE_INFO);
  if (link == nullptr) return VK_ERROR_INITIALIZATION_FAILED;
  const PFN_vkGetInstanceProcAddr next_instance_proc =
      link->u.pLayerInfo->pfnNextGetInstanceProcAddr;
  state.next_device_proc = link->u.pLayerInfo->pfnNextGetDeviceProcAddr;
  link->u.pLayerInfo = link->u.pLayerInfo->pNext;
  const auto next_create =
      reinterpret_cast<PFN_vkCreateDevice>(next_instance_proc(VK_NULL_HANDLE, "vkCreateDevice"));
  const VkResult result = next_create(physical_device, info, allocator, device);
  if (result != VK_SUCCESS) return result;
  state.device = *device;
  state.next_submit2 =
      reinterpret_cast<PFN_vkQueueSubmit2>(state.next_device_proc(*device, "vkQueueSubmit2"));
  state.next_wait_for_fences =
      reinterpret_cast<PFN_vkWaitForFences>(state.next_device_proc(*device, "vkWaitForFences"));
  state.next_device_wait_idle =
      reinterpret_cast<PFN_vkDeviceWaitIdle>(state.next_device_proc(*device, "vkDeviceWaitIdle"));
  return VK_SUCCESS;
}

PFN_vkVoidFunction own_device_function(const char* name) {
  if (std::strcmp(name, "vkQueueSubmit2") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&queue_submit2);
  }
  if (std::strcmp(name, "vkWaitForFences") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&wait_for_fences);
  }
  if (std::strcmp(name, "vkDeviceWaitIdle") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&device_wait_idle);
  }
  return nullptr;
}

// The layer's entry points by their own names: the exported ones below only forward here, so
// a global vk* symbol elsewhere in the process can never stand in for them.
PFN_vkVoidFunction VKAPI_CALL get_device_proc(VkDevice device, const char* name) {
  if (std::strcmp(name, "vkGetDeviceProcAddr") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&get_device_proc);
  }
  if (PFN_vkVoidFunction own = own_device_function(name)) return own;
  return state.next_device_proc != nullptr ? state.next_device_proc(device, name) : nullptr;
}

PFN_vkVoidFunction VKAPI_CALL get_instance_proc(VkInstance instance, const char* name) {
  if (std::strcmp(name, "vkGetInstanceProcAddr") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&get_instance_proc);
  }
  if (std::strcmp(name, "vkCreateInstance") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&create_instance);
  }
  if (std::strcmp(name, "vkCreateDevice") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&create_device);
  }
  if (std::strcmp(name, "vkGetDeviceProcAddr") == 0) {
    return reinterpret_cast<PFN_vkVoidFunction>(&get_device_proc);
  }
  if (PFN_vkVoidFunction own = own_device_function(name)) return own;
  return state.next_instance_proc != nullptr ? state.next_instance_proc(instance, name) : nullptr;
}

}  // namespace

extern "C" {

VK_LAYER_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetDeviceProcAddr(VkDevice device,
                                                                            const char* name) {
  return get_device_proc(device, name);
}

VK_LAYER_EXPORT VKAPI_ATTR PFN_vkVoidFunction VKAPI_CALL vkGetInstanceProcAddr(VkInstance instance,
                                                                              const char* name) {
  return get_instance_proc(instance, name);
}

}  // extern "C"
