#include "siviflow/headless_context.h"

#include <dlfcn.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string_view>

#include "siviflow/renderer.h"
#include "vk/device_table.h"
#include "vk/gpu_resources.h"

namespace siviflow {
namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr uint64_t kFenceTimeoutNs = 120ull * 1000 * 1000 * 1000;  // lavapipe JIT can be slow
constexpr size_t kMaxKeptMessages = 64;

// Host-side functions: what an engine's own loader would give it. Not part of DeviceTable,
// which holds only what the renderer itself may call.
#define SIVIFLOW_GLOBAL_FUNCTIONS(X)       \
  X(vkCreateInstance)                      \
  X(vkEnumerateInstanceLayerProperties)    \
  X(vkEnumerateInstanceExtensionProperties)
#define SIVIFLOW_HOST_INSTANCE_FUNCTIONS(X)      \
  X(vkDestroyInstance)                           \
  X(vkEnumeratePhysicalDevices)                  \
  X(vkGetPhysicalDeviceProperties2)              \
  X(vkGetPhysicalDeviceFeatures2)                \
  X(vkGetPhysicalDeviceQueueFamilyProperties)    \
  X(vkCreateDevice)                              \
  X(vkGetDeviceProcAddr)
#define SIVIFLOW_HOST_DEVICE_FUNCTIONS(X) \
  X(vkDestroyDevice)                      \
  X(vkGetDeviceQueue)                     \
  X(vkDeviceWaitIdle)                     \
  X(vkQueueSubmit2)                       \
  X(vkCreateCommandPool)                  \
  X(vkDestroyCommandPool)                 \
  X(vkAllocateCommandBuffers)             \
  X(vkResetCommandBuffer)                 \
  X(vkBeginCommandBuffer)                 \
  X(vkEndCommandBuffer)                   \
  X(vkCreateFence)                        \
  X(vkDestroyFence)                       \
  X(vkWaitForFences)                      \
  X(vkResetFences)

#define SIVIFLOW_DECLARE(name) PFN_##name name = nullptr;
struct HostTable {
  SIVIFLOW_GLOBAL_FUNCTIONS(SIVIFLOW_DECLARE)
  SIVIFLOW_HOST_INSTANCE_FUNCTIONS(SIVIFLOW_DECLARE)
  SIVIFLOW_HOST_DEVICE_FUNCTIONS(SIVIFLOW_DECLARE)
  PFN_vkCreateDebugUtilsMessengerEXT vkCreateDebugUtilsMessengerEXT = nullptr;
  PFN_vkDestroyDebugUtilsMessengerEXT vkDestroyDebugUtilsMessengerEXT = nullptr;
};
#undef SIVIFLOW_DECLARE

struct Loader {
  void* library = nullptr;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
};

// The loader is opened once per process and kept: closing it while the ICD's threads may still
// run is what valgrind flagged in the reliability notes.
const Loader& vulkan_loader() {
  static const Loader loader = [] {
    Loader l;
    l.library = dlopen("libvulkan.so.1", RTLD_NOW | RTLD_LOCAL);
    if (l.library != nullptr) {
      l.get_instance_proc_addr =
          reinterpret_cast<PFN_vkGetInstanceProcAddr>(dlsym(l.library, "vkGetInstanceProcAddr"));
    }
    return l;
  }();
  return loader;
}

Status vk_error(const std::string& what, VkResult result) {
  return Status::error(what + " failed: " + result_name(result), result);
}

bool has_layer(const HostTable& host, const char* name) {
  uint32_t count = 0;
  if (host.vkEnumerateInstanceLayerProperties(&count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkLayerProperties> layers(count);
  if (host.vkEnumerateInstanceLayerProperties(&count, layers.data()) != VK_SUCCESS) return false;
  for (const VkLayerProperties& layer : layers) {
    if (std::strcmp(layer.layerName, name) == 0) return true;
  }
  return false;
}

// Test seam of this standalone host only (the renderer checks the real enabled features): a comma
// list of required feature names to treat as unsupported, so the tool's "missing feature" path
// can be exercised on lavapipe, which has them all.
std::vector<std::string> hidden_features() {
  std::vector<std::string> names;
  const char* hidden = std::getenv("SIVIFLOW_HIDE_DEVICE_FEATURES");
  if (hidden == nullptr) return names;
  std::string item;
  for (const char* c = hidden;; ++c) {
    if (*c == ',' || *c == '\0') {
      if (!item.empty()) names.push_back(item);
      item.clear();
      if (*c == '\0') break;
    } else {
      item += *c;
    }
  }
  return names;
}

std::string driver_files_hint() {
  const char* files = std::getenv("VK_DRIVER_FILES");
  if (files == nullptr) files = std::getenv("VK_ICD_FILENAMES");
  return files != nullptr ? std::string(" (VK_DRIVER_FILES=") + files + ")" : std::string();
}

}  // namespace

struct HeadlessContext::Impl {
  HostTable host;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr = nullptr;
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t queue_family = 0;
  VkCommandPool pool = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> slot_commands;
  std::vector<VkFence> slot_fences;
  DeviceReport report;
  bool print_messages = true;
  RequiredDeviceFeatures enabled;  // the chain the device was created with
  DeviceTable table;  // for the host-owned images and buffers
  GpuContext gpu;
  std::vector<Image> host_images;
  std::vector<Buffer> host_buffers;

  mutable std::mutex messages_mutex;
  uint32_t error_count = 0;
  std::vector<std::string> errors;

  static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(
      VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<Impl*>(user);
    const char* id = data->pMessageIdName != nullptr ? data->pMessageIdName : "";
    const bool is_error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
    if (is_error) {
      std::lock_guard<std::mutex> lock(self->messages_mutex);
      ++self->error_count;
      if (self->errors.size() < kMaxKeptMessages) {
        self->errors.push_back(std::string(id) + ": " + data->pMessage);
      }
    }
    if (self->print_messages) {
      std::fprintf(stderr, "[vulkan %s] %s: %s\n", is_error ? "error" : "warning", id,
                   data->pMessage);
    }
    return VK_FALSE;  // never abort the call that triggered the message
  }

  VkDebugUtilsMessengerCreateInfoEXT messenger_info() {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                           VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                       VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    info.pfnUserCallback = &Impl::on_message;
    info.pUserData = this;
    return info;
  }

  Status create_instance(const HeadlessContextOptions& options);
  Status pick_device(const HeadlessContextOptions& options);
  Status create_device();
  Status create_command_objects();
  void destroy();
};

Status HeadlessContext::Impl::create_instance(const HeadlessContextOptions& options) {
  const Loader& loader = vulkan_loader();
  if (loader.get_instance_proc_addr == nullptr) {
    return Status::error("cannot load the Vulkan loader libvulkan.so.1: " +
                         std::string(dlerror() != nullptr ? dlerror() : "not found"));
  }
  get_instance_proc_addr = loader.get_instance_proc_addr;
#define SIVIFLOW_LOAD_GLOBAL(name) \
  host.name = reinterpret_cast<PFN_##name>(get_instance_proc_addr(VK_NULL_HANDLE, #name));
  SIVIFLOW_GLOBAL_FUNCTIONS(SIVIFLOW_LOAD_GLOBAL)
#undef SIVIFLOW_LOAD_GLOBAL

  report.validation_layer_available = has_layer(host, kValidationLayer);
  const bool use_validation = options.enable_validation && report.validation_layer_available;
  if (options.enable_validation && options.require_validation && !use_validation) {
    return Status::error(std::string("the validation layer ") + kValidationLayer +
                             " is required but not installed (package vulkan-validationlayers)",
                         VK_ERROR_LAYER_NOT_PRESENT);
  }
  report.validation_enabled = use_validation;

  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "siviflow";
  app.pEngineName = "siviflow";
  app.apiVersion = VK_API_VERSION_1_3;

  std::vector<const char*> layers;
  std::vector<const char*> extensions;
  // Chain: instance -> messenger info -> validation features, so that messages emitted while
  // creating and destroying the instance are counted too.
  VkDebugUtilsMessengerCreateInfoEXT chained_messenger = messenger_info();
  const VkValidationFeatureEnableEXT enables[] = {
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT};
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = enables;

  VkInstanceCreateInfo create{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  create.pApplicationInfo = &app;
  if (use_validation) {
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
    chained_messenger.pNext = &features;
    create.pNext = &chained_messenger;
  }
  create.enabledLayerCount = static_cast<uint32_t>(layers.size());
  create.ppEnabledLayerNames = layers.data();
  create.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  create.ppEnabledExtensionNames = extensions.data();

  VkResult result = host.vkCreateInstance(&create, nullptr, &instance);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) {
    return Status::error("no Vulkan driver found" + driver_files_hint() +
                             ": vkCreateInstance returned VK_ERROR_INCOMPATIBLE_DRIVER",
                         result);
  }
  if (result != VK_SUCCESS) return vk_error("vkCreateInstance", result);

#define SIVIFLOW_LOAD_INSTANCE(name) \
  host.name = reinterpret_cast<PFN_##name>(get_instance_proc_addr(instance, #name));
  SIVIFLOW_HOST_INSTANCE_FUNCTIONS(SIVIFLOW_LOAD_INSTANCE)
  if (use_validation) {
    SIVIFLOW_LOAD_INSTANCE(vkCreateDebugUtilsMessengerEXT)
    SIVIFLOW_LOAD_INSTANCE(vkDestroyDebugUtilsMessengerEXT)
    VkDebugUtilsMessengerCreateInfoEXT info = messenger_info();
    result = host.vkCreateDebugUtilsMessengerEXT(instance, &info, nullptr, &messenger);
    if (result != VK_SUCCESS) return vk_error("vkCreateDebugUtilsMessengerEXT", result);
  }
#undef SIVIFLOW_LOAD_INSTANCE
  return Status::success();
}

Status HeadlessContext::Impl::pick_device(const HeadlessContextOptions& options) {
  uint32_t count = 0;
  VkResult result = host.vkEnumeratePhysicalDevices(instance, &count, nullptr);
  if (result != VK_SUCCESS) return vk_error("vkEnumeratePhysicalDevices", result);
  if (count == 0) return Status::error("no Vulkan device found" + driver_files_hint());
  std::vector<VkPhysicalDevice> devices(count);
  result = host.vkEnumeratePhysicalDevices(instance, &count, devices.data());
  if (result != VK_SUCCESS) return vk_error("vkEnumeratePhysicalDevices", result);

  std::string rejected;
  for (VkPhysicalDevice candidate : devices) {
    VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props.pNext = &driver;
    host.vkGetPhysicalDeviceProperties2(candidate, &props);
    const std::string name = props.properties.deviceName;
    if (props.properties.apiVersion < VK_API_VERSION_1_3) {
      rejected += "\n  " + name + ": Vulkan " + std::to_string(VK_API_VERSION_MAJOR(props.properties.apiVersion)) +
                  "." + std::to_string(VK_API_VERSION_MINOR(props.properties.apiVersion)) +
                  " < 1.3";
      continue;
    }
    if (options.require_lavapipe && driver.driverID != VK_DRIVER_ID_MESA_LLVMPIPE) {
      rejected += "\n  " + name + ": not Mesa lavapipe (llvmpipe) as required";
      continue;
    }
    VkPhysicalDeviceVulkan13Features supported13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    VkPhysicalDeviceFeatures2 supported{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    supported.pNext = &supported13;
    host.vkGetPhysicalDeviceFeatures2(candidate, &supported);
    std::vector<std::string> missing = missing_device_features(&supported);
    for (const std::string& hidden : hidden_features()) missing.push_back(hidden);
    if (!missing.empty()) {
      rejected += "\n  " + name + ": missing required feature";
      for (const std::string& feature : missing) rejected += " " + feature;
      continue;
    }
    uint32_t family_count = 0;
    host.vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, nullptr);
    std::vector<VkQueueFamilyProperties> families(family_count);
    host.vkGetPhysicalDeviceQueueFamilyProperties(candidate, &family_count, families.data());
    bool found_family = false;
    for (uint32_t i = 0; i < family_count; ++i) {
      if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) != 0) {
        queue_family = i;
        found_family = true;
        break;
      }
    }
    if (!found_family) {
      rejected += "\n  " + name + ": no graphics queue";
      continue;
    }
    physical_device = candidate;
    report.device_name = name;
    report.driver_name = driver.driverName;
    report.driver_info = driver.driverInfo;
    report.driver_id = driver.driverID;
    report.device_type = props.properties.deviceType;
    report.api_version = props.properties.apiVersion;
    report.max_image_dimension_2d = props.properties.limits.maxImageDimension2D;
    return Status::success();
  }
  return Status::error("no suitable Vulkan 1.3 device:" + rejected, VK_ERROR_FEATURE_NOT_PRESENT);
}

Status HeadlessContext::Impl::create_device() {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;

  enabled = required_device_features();
  enabled.link();
  VkDeviceCreateInfo create{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  create.pNext = &enabled.features2;
  create.queueCreateInfoCount = 1;
  create.pQueueCreateInfos = &queue_info;
  VkResult result = host.vkCreateDevice(physical_device, &create, nullptr, &device);
  if (result != VK_SUCCESS) return vk_error("vkCreateDevice", result);
#define SIVIFLOW_LOAD_DEVICE(name) \
  host.name = reinterpret_cast<PFN_##name>(host.vkGetDeviceProcAddr(device, #name));
  SIVIFLOW_HOST_DEVICE_FUNCTIONS(SIVIFLOW_LOAD_DEVICE)
#undef SIVIFLOW_LOAD_DEVICE
  host.vkGetDeviceQueue(device, queue_family, 0, &queue);
  const char* missing = nullptr;
  result = load_device_table(instance, physical_device, device, get_instance_proc_addr,
                             host.vkGetDeviceProcAddr, report.validation_enabled, &table, &missing);
  if (result != VK_SUCCESS) return Status::error(std::string("cannot load ") + missing, result);
  gpu = make_gpu_context(table, nullptr);
  return Status::success();
}

Status HeadlessContext::Impl::create_command_objects() {
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = queue_family;
  VkResult result = host.vkCreateCommandPool(device, &pool_info, nullptr, &pool);
  if (result != VK_SUCCESS) return vk_error("vkCreateCommandPool", result);
  return Status::success();
}

void HeadlessContext::Impl::destroy() {
  if (device != VK_NULL_HANDLE) {
    host.vkDeviceWaitIdle(device);
    for (VkFence fence : slot_fences) host.vkDestroyFence(device, fence, nullptr);
    if (pool != VK_NULL_HANDLE) host.vkDestroyCommandPool(device, pool, nullptr);
    for (Image& image : host_images) destroy_image(gpu, &image);
    for (Buffer& buffer : host_buffers) destroy_buffer(gpu, &buffer);
    host.vkDestroyDevice(device, nullptr);
  }
  if (messenger != VK_NULL_HANDLE) host.vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
  if (instance != VK_NULL_HANDLE) host.vkDestroyInstance(instance, nullptr);
  device = VK_NULL_HANDLE;
  instance = VK_NULL_HANDLE;
}

Status HeadlessContext::create(const HeadlessContextOptions& options,
                               std::unique_ptr<HeadlessContext>* out) {
  auto impl = std::make_unique<Impl>();
  impl->print_messages = options.print_validation_messages;
  Status status = impl->create_instance(options);
  if (status.ok()) status = impl->pick_device(options);
  if (status.ok()) status = impl->create_device();
  if (status.ok()) status = impl->create_command_objects();
  if (!status.ok()) {
    impl->destroy();
    return status;
  }
  out->reset(new HeadlessContext(std::move(impl)));
  return Status::success();
}

HeadlessContext::HeadlessContext(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
HeadlessContext::~HeadlessContext() { impl_->destroy(); }

VkInstance HeadlessContext::instance() const { return impl_->instance; }
VkPhysicalDevice HeadlessContext::physical_device() const { return impl_->physical_device; }
VkDevice HeadlessContext::device() const { return impl_->device; }
VkQueue HeadlessContext::queue() const { return impl_->queue; }
uint32_t HeadlessContext::queue_family_index() const { return impl_->queue_family; }
PFN_vkGetInstanceProcAddr HeadlessContext::get_instance_proc_addr() const {
  return impl_->get_instance_proc_addr;
}
PFN_vkGetDeviceProcAddr HeadlessContext::get_device_proc_addr() const {
  return impl_->host.vkGetDeviceProcAddr;
}
const DeviceReport& HeadlessContext::report() const { return impl_->report; }

CreateInfo HeadlessContext::renderer_create_info(VkExtent2D extent, VkFormat color_format) const {
  CreateInfo info;
  info.instance = impl_->instance;
  info.physical_device = impl_->physical_device;
  info.device = impl_->device;
  info.get_instance_proc_addr = impl_->get_instance_proc_addr;
  info.get_device_proc_addr = impl_->host.vkGetDeviceProcAddr;
  info.enabled_features = &impl_->enabled.features2;
  info.queue_family_index = impl_->queue_family;
  info.color_format = color_format;
  info.extent = extent;
  info.debug_utils = impl_->report.validation_enabled;
  return info;
}

WorldCreateInfo HeadlessContext::world_create_info(VkFormat color_format,
                                                   VkFormat depth_format) const {
  WorldCreateInfo info;
  info.instance = impl_->instance;
  info.physical_device = impl_->physical_device;
  info.device = impl_->device;
  info.get_instance_proc_addr = impl_->get_instance_proc_addr;
  info.get_device_proc_addr = impl_->host.vkGetDeviceProcAddr;
  info.color_format = color_format;
  info.depth_format = depth_format;
  info.debug_utils = impl_->report.validation_enabled;
  info.queue_family_index = impl_->queue_family;
  return info;
}

Status HeadlessContext::begin_slot(uint32_t slot, VkCommandBuffer* cmd) {
  Impl& s = *impl_;
  while (s.slot_commands.size() <= slot) {
    VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    alloc.commandPool = s.pool;
    alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    alloc.commandBufferCount = 1;
    VkCommandBuffer buffer = VK_NULL_HANDLE;
    VkResult result = s.host.vkAllocateCommandBuffers(s.device, &alloc, &buffer);
    if (result != VK_SUCCESS) return vk_error("vkAllocateCommandBuffers", result);
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    VkFence fence = VK_NULL_HANDLE;
    result = s.host.vkCreateFence(s.device, &fence_info, nullptr, &fence);
    if (result != VK_SUCCESS) return vk_error("vkCreateFence", result);
    s.slot_commands.push_back(buffer);
    s.slot_fences.push_back(fence);
  }
  SIVIFLOW_TRY(wait_slot(slot));
  VkResult result = s.host.vkResetCommandBuffer(s.slot_commands[slot], 0);
  if (result != VK_SUCCESS) return vk_error("vkResetCommandBuffer", result);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  result = s.host.vkBeginCommandBuffer(s.slot_commands[slot], &begin);
  if (result != VK_SUCCESS) return vk_error("vkBeginCommandBuffer", result);
  *cmd = s.slot_commands[slot];
  return Status::success();
}

Status HeadlessContext::end_slot_and_submit(uint32_t slot) {
  Impl& s = *impl_;
  if (slot >= s.slot_commands.size()) return Status::error("end_slot_and_submit: slot not begun");
  VkResult result = s.host.vkEndCommandBuffer(s.slot_commands[slot]);
  if (result != VK_SUCCESS) return vk_error("vkEndCommandBuffer", result);
  // Reset only now: a failure between begin_slot and here leaves the fence signalled, so the
  // next wait on this slot does not block until the timeout.
  result = s.host.vkResetFences(s.device, 1, &s.slot_fences[slot]);
  if (result != VK_SUCCESS) return vk_error("vkResetFences", result);
  VkCommandBufferSubmitInfo command_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  command_info.commandBuffer = s.slot_commands[slot];
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &command_info;
  result = s.host.vkQueueSubmit2(s.queue, 1, &submit, s.slot_fences[slot]);
  if (result != VK_SUCCESS) return vk_error("vkQueueSubmit2", result);
  return Status::success();
}

Status HeadlessContext::wait_slot(uint32_t slot) {
  Impl& s = *impl_;
  if (slot >= s.slot_fences.size()) return Status::success();
  const VkResult result =
      s.host.vkWaitForFences(s.device, 1, &s.slot_fences[slot], VK_TRUE, kFenceTimeoutNs);
  if (result == VK_TIMEOUT) return Status::error("GPU frame did not finish in time (fence timeout)", result);
  if (result != VK_SUCCESS) return vk_error("vkWaitForFences", result);
  return Status::success();
}

Status HeadlessContext::wait_idle() {
  const VkResult result = impl_->host.vkDeviceWaitIdle(impl_->device);
  if (result != VK_SUCCESS) return vk_error("vkDeviceWaitIdle", result);
  return Status::success();
}

Status HeadlessContext::create_target_image(VkFormat format, VkExtent2D extent, HostImage* out) {
  Image image;
  const VkImageUsageFlags usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                  VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  SIVIFLOW_TRY(create_image(impl_->gpu, format, extent, usage, "host target", &image));
  impl_->host_images.push_back(image);
  *out = HostImage{image.image, image.view, usage};
  return Status::success();
}

Status HeadlessContext::create_depth_image(VkFormat format, VkExtent2D extent, HostImage* out) {
  Image image;
  const VkImageUsageFlags usage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                  VK_IMAGE_USAGE_TRANSFER_SRC_BIT | VK_IMAGE_USAGE_SAMPLED_BIT;
  SIVIFLOW_TRY(create_image(impl_->gpu, format, extent, usage, "host depth", &image));
  impl_->host_images.push_back(image);
  *out = HostImage{image.image, image.view, usage};
  return Status::success();
}

Status HeadlessContext::create_readback_buffer(VkDeviceSize size, HostBuffer* out) {
  Buffer buffer;
  SIVIFLOW_TRY(create_buffer(impl_->gpu, size, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             /*host_visible=*/true, "host readback", &buffer));
  impl_->host_buffers.push_back(buffer);
  *out = HostBuffer{buffer.buffer, buffer.mapped};
  return Status::success();
}

uint32_t HeadlessContext::validation_error_count() const {
  std::lock_guard<std::mutex> lock(impl_->messages_mutex);
  return impl_->error_count;
}

std::vector<std::string> HeadlessContext::validation_errors() const {
  std::lock_guard<std::mutex> lock(impl_->messages_mutex);
  return impl_->errors;
}

bool validation_layer_present() {
  const Loader& loader = vulkan_loader();
  if (loader.get_instance_proc_addr == nullptr) return false;
  HostTable host;
  host.vkEnumerateInstanceLayerProperties = reinterpret_cast<PFN_vkEnumerateInstanceLayerProperties>(
      loader.get_instance_proc_addr(VK_NULL_HANDLE, "vkEnumerateInstanceLayerProperties"));
  return host.vkEnumerateInstanceLayerProperties != nullptr && has_layer(host, kValidationLayer);
}

}  // namespace siviflow
