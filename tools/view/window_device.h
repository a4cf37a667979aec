// The viewer's own Vulkan host, as an engine has one: a GLFW window, an instance with the
// window system's surface extensions (and the validation layer when asked), the surface, and a
// Vulkan 1.3 device that can present to it with the water renderer's required features on.
// Calls Vulkan through the loader it links, like any application.
#pragma once

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

#include "siviflow/renderer.h"
#include "siviflow/status.h"

namespace siviflow::view {

struct WindowDeviceOptions {
  uint32_t width = 1280;
  uint32_t height = 720;
  bool validation = false;  // the Khronos layer with synchronization validation, errors counted
};

class WindowDevice {
 public:
  // Fails with a message when there is no display, GLFW cannot start, Vulkan has no surface
  // support, or no device can both render the water and present to the window (each refused
  // device named with its reason).
  Status create(const WindowDeviceOptions& options);
  ~WindowDevice();

  GLFWwindow* window = nullptr;
  VkInstance instance = VK_NULL_HANDLE;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  std::string device_name;
  bool validation = false;
  RequiredDeviceFeatures enabled;  // the chain the device was created with

  uint32_t validation_error_count() const;
  // A renderer CreateInfo for this device; the caller sets the rest.
  CreateInfo renderer_create_info(VkExtent2D extent) const;
  // A memory type index with `properties` among `type_bits`, or UINT32_MAX.
  uint32_t memory_type(uint32_t type_bits, VkMemoryPropertyFlags properties) const;

 private:
  Status create_window(const WindowDeviceOptions& options);
  Status create_instance();
  Status pick_device();
  Status create_device();
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(
      VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT type,
      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);

  bool glfw_started_ = false;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  mutable std::mutex messages_mutex_;
  uint32_t error_count_ = 0;
};

// "VK_ERROR_OUT_OF_DATE_KHR" style text for a failed call.
Status vk_failure(const char* call, VkResult result);

}  // namespace siviflow::view
