// A windowed engine around an installed SiViFlow: a GLFW window, a swapchain, two frames in
// flight, an HDR scene colour (R16G16B16A16_SFLOAT) that the engine draws its world into (here a
// sky clear and ground far below the water), the water recorded over it, and the frame blitted
// to the swapchain image and presented. The engine reflects its own world in the water through
// CreateInfo::reflection: its world is a uniform sky, so its mirrored world is that sky, drawn
// into the reflection target by the callback. Runs until the window closes, or N frames with
// --frames N; exits 0 only when every frame was presented, the callback drew every frame's
// reflection, the last frame shows water and sky, and the validation layer (when installed)
// reported no error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <siviflow/renderer.h>
#define GLFW_INCLUDE_VULKAN
#include <GLFW/glfw3.h>

namespace {

constexpr VkExtent2D kExtent{640, 360};
constexpr uint32_t kFramesInFlight = 2;
constexpr VkFormat kColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr float kSky[4] = {0.45f, 0.6f, 0.8f, 1.0f};
constexpr VkImageUsageFlags kColorUsage =
    VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
constexpr VkImageUsageFlags kDepthUsage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                          VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
constexpr uint64_t kTimeout = 10'000'000'000ull;

unsigned g_validation_errors = 0;

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    ++g_validation_errors;
    std::fprintf(stderr, "validation: %s\n", data->pMessage);
  }
  return VK_FALSE;
}

bool has_layer(const char* name) {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const VkLayerProperties& layer : layers) {
    if (std::strcmp(layer.layerName, name) == 0) return true;
  }
  return false;
}

// The engine's reflection: its world mirrored about the water. This engine's world is a uniform
// sky, so the mirrored world is the same sky, opaque (alpha 1: "the engine drew here").
void reflect_world(VkCommandBuffer cmd, const siviflow::ReflectionView& view, void* user) {
  VkClearAttachment sky{VK_IMAGE_ASPECT_COLOR_BIT, 0, {}};
  std::memcpy(sky.clearValue.color.float32, kSky, sizeof(kSky));
  const VkClearRect all{{{0, 0}, view.extent}, 0, 1};
  vkCmdClearAttachments(cmd, 1, &sky, 1, &all);
  ++*static_cast<unsigned*>(user);
}

// One image-layout transition, the way every barrier of this engine is written.
void transition(VkCommandBuffer cmd, VkImage image, VkImageAspectFlags aspect,
                VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access, VkImageLayout from,
                VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access, VkImageLayout to) {
  VkImageMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  barrier.srcStageMask = src_stage;
  barrier.srcAccessMask = src_access;
  barrier.dstStageMask = dst_stage;
  barrier.dstAccessMask = dst_access;
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = {aspect, 0, 1, 0, 1};
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.imageMemoryBarrierCount = 1;
  dependency.pImageMemoryBarriers = &barrier;
  vkCmdPipelineBarrier2(cmd, &dependency);
}

struct FrameSlot {
  VkImage color = VK_NULL_HANDLE, depth = VK_NULL_HANDLE;
  VkImageView color_view = VK_NULL_HANDLE, depth_view = VK_NULL_HANDLE;
  VkBuffer readback = VK_NULL_HANDLE;
  VkDeviceMemory readback_memory = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkSemaphore acquired = VK_NULL_HANDLE;
};

struct Engine {
  GLFWwindow* window = nullptr;
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkSurfaceKHR surface = VK_NULL_HANDLE;
  VkPhysicalDevice gpu = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain = VK_NULL_HANDLE;
  std::vector<VkImage> swapchain_images;
  std::vector<VkSemaphore> rendered;  // one per swapchain image: its present waits on it
  VkCommandPool pool = VK_NULL_HANDLE;
  FrameSlot slots[kFramesInFlight];
  std::vector<VkImage> images;
  std::vector<VkImageView> views;
  std::vector<VkBuffer> buffers;
  std::vector<VkDeviceMemory> memories;

  ~Engine() {
    if (device != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(device);
      for (FrameSlot& slot : slots) {
        vkDestroyFence(device, slot.fence, nullptr);
        vkDestroySemaphore(device, slot.acquired, nullptr);
      }
      for (VkSemaphore semaphore : rendered) vkDestroySemaphore(device, semaphore, nullptr);
      vkDestroyCommandPool(device, pool, nullptr);
      for (VkBuffer buffer : buffers) vkDestroyBuffer(device, buffer, nullptr);
      for (VkImageView view : views) vkDestroyImageView(device, view, nullptr);
      for (VkImage image : images) vkDestroyImage(device, image, nullptr);
      for (VkDeviceMemory memory : memories) vkFreeMemory(device, memory, nullptr);
      vkDestroySwapchainKHR(device, swapchain, nullptr);
      vkDestroyDevice(device, nullptr);
    }
    if (surface != VK_NULL_HANDLE) vkDestroySurfaceKHR(instance, surface, nullptr);
    if (messenger != VK_NULL_HANDLE) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroy(instance, messenger, nullptr);
    }
    if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
    if (window != nullptr) glfwDestroyWindow(window);
    glfwTerminate();
  }

  bool bind(VkMemoryRequirements needs, VkMemoryPropertyFlags wanted, VkDeviceMemory* out) {
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(gpu, &props);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = needs.size;
    alloc.memoryTypeIndex = UINT32_MAX;
    for (uint32_t i = 0; i < props.memoryTypeCount && alloc.memoryTypeIndex == UINT32_MAX; ++i) {
      if ((needs.memoryTypeBits & (1u << i)) && (props.memoryTypes[i].propertyFlags & wanted) == wanted) {
        alloc.memoryTypeIndex = i;
      }
    }
    if (alloc.memoryTypeIndex == UINT32_MAX) return false;
    if (vkAllocateMemory(device, &alloc, nullptr, out) != VK_SUCCESS) return false;
    memories.push_back(*out);
    return true;
  }

  bool image(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect, VkImage* out,
             VkImageView* view) {
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {kExtent.width, kExtent.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.usage = usage;
    if (vkCreateImage(device, &info, nullptr, out) != VK_SUCCESS) return false;
    images.push_back(*out);
    VkMemoryRequirements needs;
    vkGetImageMemoryRequirements(device, *out, &needs);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    if (!bind(needs, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &memory)) return false;
    vkBindImageMemory(device, *out, memory, 0);
    VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view_info.image = *out;
    view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view_info.format = format;
    view_info.subresourceRange = {aspect, 0, 1, 0, 1};
    if (vkCreateImageView(device, &view_info, nullptr, view) != VK_SUCCESS) return false;
    views.push_back(*view);
    return true;
  }
};

int fail(const char* what) {
  std::fprintf(stderr, "window_host: %s\n", what);
  return 1;
}

bool create_instance(Engine& e, bool validate) {
  uint32_t glfw_count = 0;
  const char** glfw_extensions = glfwGetRequiredInstanceExtensions(&glfw_count);
  std::vector<const char*> extensions(glfw_extensions, glfw_extensions + glfw_count);
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &sync;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "window_host";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  if (validate) {
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    info.pNext = &features;
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
  }
  info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  if (vkCreateInstance(&info, nullptr, &e.instance) != VK_SUCCESS) return false;
  if (!validate) return true;
  VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  messenger.pfnUserCallback = &on_message;
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(e.instance, "vkCreateDebugUtilsMessengerEXT"));
  return create(e.instance, &messenger, nullptr, &e.messenger) == VK_SUCCESS;
}

// The first device with SiViFlow's features and a graphics queue that can present to the window.
bool create_device(Engine& e, siviflow::RequiredDeviceFeatures* required) {
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(e.instance, &count, nullptr);
  std::vector<VkPhysicalDevice> gpus(count);
  vkEnumeratePhysicalDevices(e.instance, &count, gpus.data());
  for (VkPhysicalDevice gpu : gpus) {
    siviflow::RequiredDeviceFeatures supported{};
    supported.features2.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2;
    supported.vulkan13.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES;
    supported.link();
    vkGetPhysicalDeviceFeatures2(gpu, &supported.features2);
    if (!siviflow::missing_device_features(&supported.features2).empty()) continue;
    uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(gpu, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(gpu, &families, props.data());
    for (uint32_t f = 0; f < families && e.gpu == VK_NULL_HANDLE; ++f) {
      VkBool32 present = VK_FALSE;
      vkGetPhysicalDeviceSurfaceSupportKHR(gpu, f, e.surface, &present);
      if ((props[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) && present) {
        e.gpu = gpu;
        e.family = f;
      }
    }
    if (e.gpu != VK_NULL_HANDLE) break;
  }
  if (e.gpu == VK_NULL_HANDLE) return false;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = e.family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  const char* swapchain_extension = VK_KHR_SWAPCHAIN_EXTENSION_NAME;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.pNext = &required->features2;
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue_info;
  info.enabledExtensionCount = 1;
  info.ppEnabledExtensionNames = &swapchain_extension;
  if (vkCreateDevice(e.gpu, &info, nullptr, &e.device) != VK_SUCCESS) return false;
  vkGetDeviceQueue(e.device, e.family, 0, &e.queue);
  return true;
}

// A FIFO swapchain of the window's size, its images written by a blit.
bool create_swapchain(Engine& e) {
  VkSurfaceCapabilitiesKHR caps;
  vkGetPhysicalDeviceSurfaceCapabilitiesKHR(e.gpu, e.surface, &caps);
  uint32_t count = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(e.gpu, e.surface, &count, nullptr);
  std::vector<VkSurfaceFormatKHR> formats(count);
  vkGetPhysicalDeviceSurfaceFormatsKHR(e.gpu, e.surface, &count, formats.data());
  if (formats.empty() || !(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT)) return false;
  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = e.surface;
  info.minImageCount = caps.maxImageCount == 0 ? caps.minImageCount + 1
                                               : std::min(caps.minImageCount + 1, caps.maxImageCount);
  info.imageFormat = formats[0].format;
  info.imageColorSpace = formats[0].colorSpace;
  info.imageExtent = kExtent;
  info.imageArrayLayers = 1;
  info.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  info.presentMode = VK_PRESENT_MODE_FIFO_KHR;
  info.clipped = VK_TRUE;
  if (vkCreateSwapchainKHR(e.device, &info, nullptr, &e.swapchain) != VK_SUCCESS) return false;
  vkGetSwapchainImagesKHR(e.device, e.swapchain, &count, nullptr);
  e.swapchain_images.resize(count);
  vkGetSwapchainImagesKHR(e.device, e.swapchain, &count, e.swapchain_images.data());
  const VkSemaphoreCreateInfo semaphore_info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
  e.rendered.resize(count);
  for (VkSemaphore& semaphore : e.rendered) {
    if (vkCreateSemaphore(e.device, &semaphore_info, nullptr, &semaphore) != VK_SUCCESS) return false;
  }
  return true;
}

bool create_slots(Engine& e, VkDeviceSize readback_bytes) {
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = e.family;
  if (vkCreateCommandPool(e.device, &pool_info, nullptr, &e.pool) != VK_SUCCESS) return false;
  for (FrameSlot& slot : e.slots) {
    if (!e.image(kColorFormat, kColorUsage, VK_IMAGE_ASPECT_COLOR_BIT, &slot.color, &slot.color_view) ||
        !e.image(kDepthFormat, kDepthUsage, VK_IMAGE_ASPECT_DEPTH_BIT, &slot.depth, &slot.depth_view)) {
      return false;
    }
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = readback_bytes;
    buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    if (vkCreateBuffer(e.device, &buffer_info, nullptr, &slot.readback) != VK_SUCCESS) return false;
    e.buffers.push_back(slot.readback);
    VkMemoryRequirements needs;
    vkGetBufferMemoryRequirements(e.device, slot.readback, &needs);
    if (!e.bind(needs, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
                &slot.readback_memory)) {
      return false;
    }
    vkBindBufferMemory(e.device, slot.readback, slot.readback_memory, 0);
    VkCommandBufferAllocateInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    cmd_info.commandPool = e.pool;
    cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    cmd_info.commandBufferCount = 1;
    if (vkAllocateCommandBuffers(e.device, &cmd_info, &slot.cmd) != VK_SUCCESS) return false;
    VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;
    const VkSemaphoreCreateInfo semaphore_info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    if (vkCreateFence(e.device, &fence_info, nullptr, &slot.fence) != VK_SUCCESS ||
        vkCreateSemaphore(e.device, &semaphore_info, nullptr, &slot.acquired) != VK_SUCCESS) {
      return false;
    }
  }
  return true;
}

// The engine's world: a sky over everything, and its depth far below the water.
void record_world(VkCommandBuffer cmd, const FrameSlot& slot) {
  transition(cmd, slot.color, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
             VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  transition(cmd, slot.depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
             VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  VkClearColorValue sky;
  std::memcpy(sky.float32, kSky, sizeof(kSky));
  const VkImageSubresourceRange color_range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  const VkImageSubresourceRange depth_range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(cmd, slot.color, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &sky, 1, &color_range);
  const VkClearDepthStencilValue ground{0.9999f, 0};
  vkCmdClearDepthStencilImage(cmd, slot.depth, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &ground, 1,
                              &depth_range);
}

// The finished frame onto the swapchain image, left ready to present.
void record_present_copy(VkCommandBuffer cmd, const FrameSlot& slot, VkImage target) {
  transition(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_NONE,
             VK_IMAGE_LAYOUT_UNDEFINED, VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
             VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
  VkImageBlit blit{};
  blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  blit.srcOffsets[1] = {static_cast<int32_t>(kExtent.width), static_cast<int32_t>(kExtent.height), 1};
  blit.dstSubresource = blit.srcSubresource;
  blit.dstOffsets[1] = blit.srcOffsets[1];
  vkCmdBlitImage(cmd, slot.color, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, target,
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_NEAREST);
  // A layout transition runs in no stage: only the barrier's second scope (every stage) chains
  // it into the semaphore the submit signals and the present waits on.
  transition(cmd, target, VK_IMAGE_ASPECT_COLOR_BIT, VK_PIPELINE_STAGE_2_BLIT_BIT,
             VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
             VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_NONE,
             VK_IMAGE_LAYOUT_PRESENT_SRC_KHR);
}

// Texels of a read-back RGBA16F frame that kept the sky, and those the water covered.
void count_texels(const Engine& e, const FrameSlot& slot, VkDeviceSize bytes, unsigned* sky_texels,
                  unsigned* water_texels) {
  void* mapped = nullptr;
  vkMapMemory(e.device, slot.readback_memory, 0, bytes, 0, &mapped);
  const auto* halves = static_cast<const uint16_t*>(mapped);
  for (VkDeviceSize i = 0; i < bytes / 2; i += 4) {
    bool is_sky = true;
    for (int c = 0; c < 3; ++c) {
      // A half's exponent and top mantissa bits: within 1/64 of the sky's value.
      const uint16_t h = halves[i + c];
      const float value = std::ldexp(1.0f + (h & 0x3ff) / 1024.0f, ((h >> 10) & 0x1f) - 15);
      is_sky = is_sky && std::abs(value - kSky[c]) < 1.0f / 64.0f;
    }
    (is_sky ? *sky_texels : *water_texels) += 1;
  }
  vkUnmapMemory(e.device, slot.readback_memory);
}

}  // namespace

int main(int argc, char** argv) {
  long frames_wanted = 0;  // 0: until the window closes
  if (argc == 3 && std::string(argv[1]) == "--frames") frames_wanted = std::strtol(argv[2], nullptr, 10);
  if (argc != 1 && (argc != 3 || frames_wanted <= 0)) return fail("usage: window_host [--frames N]");
  if (!glfwInit()) return fail("no display GLFW can open (DISPLAY or WAYLAND_DISPLAY)");
  Engine e;
  glfwWindowHint(GLFW_CLIENT_API, GLFW_NO_API);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  e.window = glfwCreateWindow(kExtent.width, kExtent.height, "SiViFlow window host", nullptr, nullptr);
  if (e.window == nullptr) return fail("glfwCreateWindow");
  const bool validate = has_layer("VK_LAYER_KHRONOS_validation");
  if (!create_instance(e, validate)) return fail("vkCreateInstance");
  if (glfwCreateWindowSurface(e.instance, e.window, nullptr, &e.surface) != VK_SUCCESS) {
    return fail("glfwCreateWindowSurface");
  }
  siviflow::RequiredDeviceFeatures required = siviflow::required_device_features();
  required.link();
  if (!create_device(e, &required)) return fail("no device with SiViFlow's features that presents");
  const VkDeviceSize bytes = VkDeviceSize{kExtent.width} * kExtent.height * 8;
  if (!create_swapchain(e) || !create_slots(e, bytes)) return fail("swapchain or frame slots");

  // SiViFlow, with the engine's reflection callback and the colour read back for the checks.
  unsigned reflections_drawn = 0;
  siviflow::CreateInfo info{};
  info.instance = e.instance;
  info.physical_device = e.gpu;
  info.device = e.device;
  info.get_instance_proc_addr = vkGetInstanceProcAddr;
  info.enabled_features = &required.features2;
  info.queue_family_index = e.family;
  info.frames_in_flight = kFramesInFlight;
  info.color_format = kColorFormat;
  info.depth_format = kDepthFormat;
  info.extent = kExtent;
  info.reflection = &reflect_world;
  info.reflection_user = &reflections_drawn;
  info.readback_images = siviflow::readback_bit(siviflow::ReadbackImage::kColor);
  std::unique_ptr<siviflow::Renderer> water;
  siviflow::Status status = siviflow::Renderer::create(info, &water);
  if (!status.ok()) return fail(status.message().c_str());

  const siviflow::ImageState cleared{VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL};
  const siviflow::ImageState blit_source{VK_PIPELINE_STAGE_2_BLIT_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  const siviflow::ImageState depth_sampled{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                           VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                                           VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL};
  long presented = 0;
  while (!glfwWindowShouldClose(e.window) && (frames_wanted == 0 || presented < frames_wanted)) {
    glfwPollEvents();
    FrameSlot& slot = e.slots[presented % kFramesInFlight];
    if (vkWaitForFences(e.device, 1, &slot.fence, VK_TRUE, kTimeout) != VK_SUCCESS) return fail("wait");
    uint32_t index = 0;
    if (vkAcquireNextImageKHR(e.device, e.swapchain, kTimeout, slot.acquired, VK_NULL_HANDLE, &index) !=
        VK_SUCCESS) {
      return fail("vkAcquireNextImageKHR");  // the window does not resize: the swapchain stays valid
    }
    vkResetFences(e.device, 1, &slot.fence);
    status = water->begin_frame(static_cast<uint32_t>(presented % kFramesInFlight));
    if (!status.ok()) return fail(status.message().c_str());
    siviflow::Camera camera;  // gliding down the river at 12 m/s
    const double seconds = presented / 60.0;
    camera.position = {0.0f, 10.0f, static_cast<float>(-60.0 + 12.0 * seconds)};
    camera.target = {6.0f, 0.0f, static_cast<float>(-30.0 + 12.0 * seconds)};
    status = water->update(siviflow::camera_view(camera, kExtent), seconds);
    if (!status.ok()) return fail(status.message().c_str());

    vkResetCommandBuffer(slot.cmd, 0);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(slot.cmd, &begin);
    record_world(slot.cmd, slot);
    siviflow::FrameInputs inputs;
    inputs.color = {slot.color, slot.color_view, kColorFormat, kExtent, cleared, blit_source, kColorUsage};
    inputs.depth = {slot.depth, slot.depth_view, kDepthFormat, kExtent, cleared, depth_sampled, kDepthUsage};
    inputs.readback[siviflow::ReadbackImage::kColor] = slot.readback;
    status = water->record(slot.cmd, inputs);
    if (!status.ok()) return fail(status.message().c_str());
    record_present_copy(slot.cmd, slot, e.swapchain_images[index]);
    vkEndCommandBuffer(slot.cmd);

    const VkPipelineStageFlags wait_stage = VK_PIPELINE_STAGE_TRANSFER_BIT;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = &slot.acquired;
    submit.pWaitDstStageMask = &wait_stage;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &slot.cmd;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &e.rendered[index];
    if (vkQueueSubmit(e.queue, 1, &submit, slot.fence) != VK_SUCCESS) return fail("submit");
    VkPresentInfoKHR present{VK_STRUCTURE_TYPE_PRESENT_INFO_KHR};
    present.waitSemaphoreCount = 1;
    present.pWaitSemaphores = &e.rendered[index];
    present.swapchainCount = 1;
    present.pSwapchains = &e.swapchain;
    present.pImageIndices = &index;
    if (vkQueuePresentKHR(e.queue, &present) != VK_SUCCESS) return fail("vkQueuePresentKHR");
    ++presented;
  }

  // The last frame: water on part of it, the engine's sky elsewhere.
  vkDeviceWaitIdle(e.device);
  unsigned sky_texels = 0, water_texels = 0;
  if (presented > 0) {
    count_texels(e, e.slots[(presented - 1) % kFramesInFlight], bytes, &sky_texels, &water_texels);
  }
  water.reset();
  std::printf("%ld frames presented, %u reflections drawn by the engine, last frame: water texels "
              "%u, sky texels %u; validation %s, errors %u\n",
              presented, reflections_drawn, water_texels, sky_texels,
              validate ? "on" : "not installed", g_validation_errors);
  const bool ok = presented > 0 && reflections_drawn == static_cast<unsigned>(presented) &&
                  water_texels > 1000 && sky_texels > 1000 && g_validation_errors == 0;
  return ok ? 0 : 1;
}
