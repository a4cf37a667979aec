#include "view/window_device.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "vk/device_table.h"

namespace siviflow::view {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

// GLFW reports errors through a callback; the last one explains a failed call.
std::string g_glfw_error;  // the viewer's only global: GLFW's error callback takes no user data
void on_glfw_error(int code, const char* description) {
  g_glfw_error = std::string(description != nullptr ? description : "") + " (GLFW error " +
                 std::to_string(code) + ")";
}

bool has_device_extension(VkPhysicalDevice device, const char* name) {
  uint32_t count = 0;
  if (vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr) != VK_SUCCESS) {
    return false;
  }
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  for (const VkExtensionProperties& e : extensions) {
    if (std::strcmp(e.extensionName, name) == 0) return true;
  }
  return false;
}

bool has_layer(const char* name) {
  uint32_t count = 0;
  if (vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const VkLayerProperties& layer : layers) {
    if (std::strcmp(layer.layerName, name) == 0) return true;
  }
  return false;
}

}  // namespace

Status vk_failure(const char* call, VkResult result) {
  return Status::error(std::string(call) + " failed: " + result_name(result), result);
}

VKAPI_ATTR VkBool32 VKAPI_CALL WindowDevice::on_message(
    VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
    const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<WindowDevice*>(user);
  const bool is_error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
  if (is_error) {
    std::lock_guard<std::mutex> lock(self->messages_mutex_);
    ++self->error_count_;
  }
  std::fprintf(stderr, "[vulkan %s] %s: %s\n", is_error ? "error" : "warning",
               data->pMessageIdName != nullptr ? data->pMessageIdName : "", data->pMessage);
  return VK_FALSE;
}

uint32_t WindowDevice::validation_error_count() const {
  std::lock_guard<std::mutex> lock(messages_mutex_);
  return error_count_;
}

Status WindowDevice::create(const WindowDeviceOptions& options) {
  validation = options.validation;
  SIVIFLOW_TRY(create_window(options));
  SIVIFLOW_TRY(create_instance());
  const VkResult result = glfwCreateWindowSurface(instance, window, nullptr, &surface);
  if (result != VK_SUCCESS) {
    return Status::error("cannot create a Vulkan surface for the window: " +
                             std::string(result_name(result)) + " " + g_glfw_error,
                         result);
  }
  SIVIFLOW_TRY(pick_device());
  return create_device();
}

Status WindowDevice::create_window(const WindowDeviceOptions& options) {
  if (std::getenv("DISPLAY") == nullptr && std::getenv("WAYLAND_DISPLAY") == nullptr) {
    return Status::error(
        "no display: neither DISPLAY nor WAYLAND_DISPLAY is set (run it in a desktop session, "
        "or under Xvfb)");
  }
  glfwSetErrorCallback(on_glfw_error);
  if (glfwInit() != GLFW_TRUE) {
    return Status::error("cannot open the display: " + g_glfw_error);
  }
  glfw_started_ = true;
  if (glfwVulkanSupported() != GLFW_TRUE) {
    return Status::error("GLFW finds no Vulkan loader with surface support: " + g_glfw_error);
  }
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_TRUE);
  window = glfwCreateWindow(static_cast<int>(options.width), static_cast<int>(options.height),
                            "SiViFlow", nullptr, nullptr);
  if (window == nullptr) return Status::error("cannot create the window: " + g_glfw_error);
  return Status::success();
}

Status WindowDevice::create_instance() {
  uint32_t glfw_count = 0;
  const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
  if (glfw_extensions == nullptr) {
    return Status::error("the Vulkan driver offers no surface for this window system: " +
                         g_glfw_error);
  }
  std::vector<const char*> extensions(glfw_extensions, glfw_extensions + glfw_count);
  std::vector<const char*> layers;
  if (validation) {
    if (!has_layer(kValidationLayer)) {
      return Status::error(std::string("--validation: the layer ") + kValidationLayer +
                           " is not installed (package vulkan-validationlayers)");
    }
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "siviflow view";
  app.apiVersion = VK_API_VERSION_1_3;
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;
  VkDebugUtilsMessengerCreateInfoEXT messenger{
      VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  messenger.pfnUserCallback = &WindowDevice::on_message;
  messenger.pUserData = this;
  messenger.pNext = &features;

  VkInstanceCreateInfo create{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  create.pNext = validation ? &messenger : nullptr;
  create.pApplicationInfo = &app;
  create.enabledLayerCount = static_cast<uint32_t>(layers.size());
  create.ppEnabledLayerNames = layers.data();
  create.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  create.ppEnabledExtensionNames = extensions.data();
  VkResult result = vkCreateInstance(&create, nullptr, &instance);
  if (result != VK_SUCCESS) return vk_failure("vkCreateInstance", result);
  if (validation) {
    auto create_messenger = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    messenger.pNext = nullptr;
    result = create_messenger(instance, &messenger, nullptr, &messenger_);
    if (result != VK_SUCCESS) return vk_failure("vkCreateDebugUtilsMessengerEXT", result);
  }
  return Status::success();
}

Status WindowDevice::pick_device() {
  uint32_t count = 0;
  VkResult result = vkEnumeratePhysicalDevices(instance, &count, nullptr);
  if (result != VK_SUCCESS) return vk_failure("vkEnumeratePhysicalDevices", result);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(instance, &count, devices.data());
  std::string rejected;
  for (VkPhysicalDevice candidate : devices) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(candidate, &props);
    const std::string name = props.deviceName;
    if (props.apiVersion < VK_API_VERSION_1_3) {
      rejected += "\n  " + name + ": not Vulkan 1.3";
      continue;
    }
    VkPhysicalDeviceVulkan13Features supported13{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceFeatures2 supported{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    supported.pNext = &supported13;
    vkGetPhysicalDeviceFeatures2(candidate, &supported);
    const std::vector<std::string> missing = missing_device_features(&supported);
    if (!missing.empty()) {
      rejected += "\n  " + name + ": missing required feature " + missing.front();
      continue;
    }
    if (!has_device_extension(candidate, VK_KHR_SWAPCHAIN_EXTENSION_NAME)) {
      rejected += "\n  " + name + ": no " VK_KHR_SWAPCHAIN_EXTENSION_NAME;
      continue;
    }
    uint32_t family_count = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, families.data());
    bool found = false;
    for (uint32_t i = 0; i < family_count && !found; ++i) {
      VkBool32 present = VK_FALSE;
      vkGetPhysicalDeviceSurfaceSupportKHR(candidate, i, surface, &present);
      if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0 && present == VK_TRUE) {
        queue_family = i;
        found = true;
      }
    }
    if (!found) {
      rejected += "\n  " + name + ": cannot present to the window (no graphics queue family "
                  "with presentation support)";
      continue;
    }
    physical_device = candidate;
    device_name = name;
    return Status::success();
  }
  return Status::error("no Vulkan 1.3 device can render the water and present to the window:" +
                       (rejected.empty() ? std::string(" no device found") : rejected));
}

Status WindowDevice::create_device() {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  enabled = required_device_features();
  enabled.link();
  const char* extensions[] = {VK_KHR_SWAPCHAIN_EXTENSION_NAME};
  VkDeviceCreateInfo create{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  create.pNext = &enabled.features2;
  create.queueCreateInfoCount = 1;
  create.pQueueCreateInfos = &queue_info;
  create.enabledExtensionCount = 1;
  create.ppEnabledExtensionNames = extensions;
  const VkResult result = vkCreateDevice(physical_device, &create, nullptr, &device);
  if (result != VK_SUCCESS) return vk_failure("vkCreateDevice", result);
  vkGetDeviceQueue(device, queue_family, 0, &queue);
  return Status::success();
}

CreateInfo WindowDevice::renderer_create_info(VkExtent2D extent) const {
  CreateInfo info;
  info.instance = instance;
  info.physical_device = physical_device;
  info.device = device;
  info.get_instance_proc_addr = vkGetInstanceProcAddr;
  info.get_device_proc_addr = vkGetDeviceProcAddr;
  info.enabled_features = &enabled.features2;
  info.queue_family_index = queue_family;
  info.extent = extent;
  info.debug_utils = validation;
  return info;
}

uint32_t WindowDevice::memory_type(uint32_t type_bits, VkMemoryPropertyFlags properties) const {
  VkPhysicalDeviceMemoryProperties memory;
  vkGetPhysicalDeviceMemoryProperties(physical_device, &memory);
  for (uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if ((type_bits & (1u << i)) != 0 &&
        (memory.memoryTypes[i].propertyFlags & properties) == properties) {
      return i;
    }
  }
  return UINT32_MAX;
}

WindowDevice::~WindowDevice() {
  if (device != VK_NULL_HANDLE) {
    vkDeviceWaitIdle(device);
    vkDestroyDevice(device, nullptr);
  }
  if (surface != VK_NULL_HANDLE) vkDestroySurfaceKHR(instance, surface, nullptr);
  if (messenger_ != VK_NULL_HANDLE) {
    auto destroy_messenger = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
    destroy_messenger(instance, messenger_, nullptr);
  }
  if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
  if (window != nullptr) glfwDestroyWindow(window);
  if (glfw_started_) glfwTerminate();
}

}  // namespace siviflow::view
