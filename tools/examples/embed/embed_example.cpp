// Embeds an installed SiViFlow as an engine would, linking siviflow::water alone: the engine
// creates its own instance and device (with the validation layer when it is installed), and per
// frame in flight its colour and depth images, command buffer, fence and readback buffer; each
// frame it draws its world into the images (here a sky-blue clear and a depth that puts the
// ground 60 m away), and SiViFlow records the default river's water over them, two frames in
// flight, the camera gliding down the river. Exits 0 only when water covers part of every frame
// read back, the rest keeps the engine's colour, and the validation layer reported no error.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include <siviflow/renderer.h>
#include <siviflow/version.h>
#include <vulkan/vulkan.h>

namespace {

constexpr VkExtent2D kExtent{96, 54};
constexpr uint32_t kFramesInFlight = 2;
constexpr uint32_t kFrames = 8;
constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr float kSky[4] = {0.45f, 0.6f, 0.8f, 1.0f};
constexpr VkImageUsageFlags kColorUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                          VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                          VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
constexpr VkImageUsageFlags kDepthUsage = VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT |
                                          VK_IMAGE_USAGE_SAMPLED_BIT |
                                          VK_IMAGE_USAGE_TRANSFER_DST_BIT;

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

uint32_t memory_type(VkPhysicalDevice gpu, uint32_t bits, VkMemoryPropertyFlags wanted) {
  VkPhysicalDeviceMemoryProperties props;
  vkGetPhysicalDeviceMemoryProperties(gpu, &props);
  for (uint32_t i = 0; i < props.memoryTypeCount; ++i) {
    if ((bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  }
  return UINT32_MAX;
}

struct Engine {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice gpu = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::vector<VkImage> images;
  std::vector<VkImageView> views;
  std::vector<VkDeviceMemory> memories;
  std::vector<VkBuffer> buffers;
  std::vector<VkFence> fences;
  VkCommandPool pool = VK_NULL_HANDLE;

  ~Engine() {
    if (device != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(device);
      for (VkFence fence : fences) vkDestroyFence(device, fence, nullptr);
      vkDestroyCommandPool(device, pool, nullptr);
      for (VkBuffer buffer : buffers) vkDestroyBuffer(device, buffer, nullptr);
      for (VkImageView view : views) vkDestroyImageView(device, view, nullptr);
      for (VkImage image : images) vkDestroyImage(device, image, nullptr);
      for (VkDeviceMemory memory : memories) vkFreeMemory(device, memory, nullptr);
      vkDestroyDevice(device, nullptr);
    }
    if (messenger != VK_NULL_HANDLE) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroy(instance, messenger, nullptr);
    }
    if (instance != VK_NULL_HANDLE) vkDestroyInstance(instance, nullptr);
  }

  bool bind(VkMemoryRequirements needs, VkMemoryPropertyFlags wanted, VkDeviceMemory* out) {
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = needs.size;
    alloc.memoryTypeIndex = memory_type(gpu, needs.memoryTypeBits, wanted);
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

// What one frame in flight owns: the engine's targets, where its colour is read back, and the
// command buffer and fence of its submission.
struct FrameSlot {
  VkImage color = VK_NULL_HANDLE, depth = VK_NULL_HANDLE;
  VkImageView color_view = VK_NULL_HANDLE, depth_view = VK_NULL_HANDLE;
  VkBuffer readback = VK_NULL_HANDLE;
  VkDeviceMemory readback_memory = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
};

bool create_slot(Engine& e, VkDeviceSize readback_bytes, FrameSlot* slot) {
  if (!e.image(kColorFormat, kColorUsage, VK_IMAGE_ASPECT_COLOR_BIT, &slot->color,
               &slot->color_view) ||
      !e.image(kDepthFormat, kDepthUsage, VK_IMAGE_ASPECT_DEPTH_BIT, &slot->depth,
               &slot->depth_view)) {
    return false;
  }
  VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  buffer_info.size = readback_bytes;
  buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  if (vkCreateBuffer(e.device, &buffer_info, nullptr, &slot->readback) != VK_SUCCESS) return false;
  e.buffers.push_back(slot->readback);
  VkMemoryRequirements needs;
  vkGetBufferMemoryRequirements(e.device, slot->readback, &needs);
  if (!e.bind(needs, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
              &slot->readback_memory)) {
    return false;
  }
  vkBindBufferMemory(e.device, slot->readback, slot->readback_memory, 0);
  VkCommandBufferAllocateInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cmd_info.commandPool = e.pool;
  cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cmd_info.commandBufferCount = 1;
  if (vkAllocateCommandBuffers(e.device, &cmd_info, &slot->cmd) != VK_SUCCESS) return false;
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  fence_info.flags = VK_FENCE_CREATE_SIGNALED_BIT;  // the first wait on each slot returns at once
  if (vkCreateFence(e.device, &fence_info, nullptr, &slot->fence) != VK_SUCCESS) return false;
  e.fences.push_back(slot->fence);
  return true;
}

// The engine's world: its colour and depth cleared (a sky, and ground far below the water).
void record_world(VkCommandBuffer cmd, const FrameSlot& slot) {
  VkImageMemoryBarrier2 to_clear[2] = {{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2},
                                       {VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2}};
  const VkImage targets[2] = {slot.color, slot.depth};
  const VkImageAspectFlags aspects[2] = {VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_ASPECT_DEPTH_BIT};
  for (int i = 0; i < 2; ++i) {
    to_clear[i].dstStageMask = VK_PIPELINE_STAGE_2_CLEAR_BIT;
    to_clear[i].dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_clear[i].oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    to_clear[i].newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    to_clear[i].srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_clear[i].dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_clear[i].image = targets[i];
    to_clear[i].subresourceRange = {aspects[i], 0, 1, 0, 1};
  }
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.imageMemoryBarrierCount = 2;
  dependency.pImageMemoryBarriers = to_clear;
  vkCmdPipelineBarrier2(cmd, &dependency);
  VkClearColorValue sky;
  std::memcpy(sky.float32, kSky, sizeof(kSky));
  const VkImageSubresourceRange color_range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  const VkImageSubresourceRange depth_range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  vkCmdClearColorImage(cmd, slot.color, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &sky, 1,
                       &color_range);
  const VkClearDepthStencilValue ground{0.9999f, 0};
  vkCmdClearDepthStencilImage(cmd, slot.depth, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &ground, 1,
                              &depth_range);
}

// Counts the texels of a read-back frame that kept the engine's sky and those the water covered.
void count_texels(const Engine& e, const FrameSlot& slot, VkDeviceSize bytes, unsigned* sky_texels,
                  unsigned* water_texels) {
  void* mapped = nullptr;
  vkMapMemory(e.device, slot.readback_memory, 0, bytes, 0, &mapped);
  const auto* texels = static_cast<const unsigned char*>(mapped);
  for (VkDeviceSize i = 0; i < bytes; i += 4) {
    bool is_sky = true;
    for (int c = 0; c < 4; ++c) {
      const int expected = static_cast<int>(kSky[c] * 255.0f + 0.5f);
      is_sky = is_sky && std::abs(texels[i + c] - expected) <= 1;
    }
    (is_sky ? *sky_texels : *water_texels) += 1;
  }
  vkUnmapMemory(e.device, slot.readback_memory);
}

int fail(const char* what) {
  std::fprintf(stderr, "embed_example: %s\n", what);
  return 1;
}

}  // namespace

int main() {
  // The headers this engine compiled against and the library it linked are the same release.
  const siviflow::Version linked = siviflow::version();
  if (linked.major != SIVIFLOW_VERSION_MAJOR || linked.minor != SIVIFLOW_VERSION_MINOR ||
      linked.patch != SIVIFLOW_VERSION_PATCH) {
    return fail("the SiViFlow library linked is not the release of its headers");
  }
  Engine e;
  // The engine's instance: Vulkan 1.3, the validation layer (synchronization validation on)
  // when it is installed.
  const bool validate = has_layer("VK_LAYER_KHRONOS_validation");
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const char* debug_utils = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  const VkValidationFeatureEnableEXT sync =
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &sync;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "embed_example";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo instance_info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  instance_info.pApplicationInfo = &app;
  if (validate) {
    instance_info.pNext = &features;
    instance_info.enabledLayerCount = 1;
    instance_info.ppEnabledLayerNames = &layer;
    instance_info.enabledExtensionCount = 1;
    instance_info.ppEnabledExtensionNames = &debug_utils;
  }
  if (vkCreateInstance(&instance_info, nullptr, &e.instance) != VK_SUCCESS)
    return fail("vkCreateInstance");
  if (validate) {
    VkDebugUtilsMessengerCreateInfoEXT messenger{
        VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    messenger.pfnUserCallback = &on_message;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(e.instance, "vkCreateDebugUtilsMessengerEXT"));
    if (create(e.instance, &messenger, nullptr, &e.messenger) != VK_SUCCESS)
      return fail("messenger");
  }

  // The first device with a graphics queue and every feature SiViFlow needs.
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(e.instance, &count, nullptr);
  std::vector<VkPhysicalDevice> gpus(count);
  vkEnumeratePhysicalDevices(e.instance, &count, gpus.data());
  siviflow::RequiredDeviceFeatures required = siviflow::required_device_features();
  required.link();
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
      if (props[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
        e.gpu = gpu;
        e.family = f;
      }
    }
    if (e.gpu != VK_NULL_HANDLE) break;
  }
  if (e.gpu == VK_NULL_HANDLE) return fail("no device with SiViFlow's required features");
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = e.family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  device_info.pNext = &required.features2;
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  if (vkCreateDevice(e.gpu, &device_info, nullptr, &e.device) != VK_SUCCESS)
    return fail("vkCreateDevice");
  vkGetDeviceQueue(e.device, e.family, 0, &e.queue);

  // The engine's command pool, and per frame in flight its targets, readback, command buffer
  // and fence.
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = e.family;
  if (vkCreateCommandPool(e.device, &pool_info, nullptr, &e.pool) != VK_SUCCESS)
    return fail("pool");
  const VkDeviceSize bytes = VkDeviceSize{kExtent.width} * kExtent.height * 4;
  FrameSlot slots[kFramesInFlight];
  for (FrameSlot& slot : slots) {
    if (!create_slot(e, bytes, &slot)) return fail("frame slot");
  }

  // SiViFlow: the default river, two frames in flight, readback of the colour into our buffers.
  siviflow::CreateInfo info{};
  info.instance = e.instance;
  info.physical_device = e.gpu;
  info.device = e.device;
  info.get_instance_proc_addr = vkGetInstanceProcAddr;
  info.get_device_proc_addr = vkGetDeviceProcAddr;
  info.enabled_features = &required.features2;
  info.queue_family_index = e.family;
  info.frames_in_flight = kFramesInFlight;
  info.color_format = kColorFormat;
  info.depth_format = kDepthFormat;
  info.extent = kExtent;
  info.readback_images = siviflow::readback_bit(siviflow::ReadbackImage::kColor);
  std::unique_ptr<siviflow::Renderer> water;
  siviflow::Status status = siviflow::Renderer::create(info, &water);
  if (!status.ok()) return fail(status.message().c_str());

  // The frame loop: the CPU fills one slot while the GPU may still render the other.
  const siviflow::ImageState cleared{VK_PIPELINE_STAGE_2_CLEAR_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                     VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL};
  const siviflow::ImageState copy_source{VK_PIPELINE_STAGE_2_COPY_BIT,
                                         VK_ACCESS_2_TRANSFER_READ_BIT,
                                         VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  const siviflow::ImageState depth_sampled{VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                                           VK_ACCESS_2_SHADER_SAMPLED_READ_BIT,
                                           VK_IMAGE_LAYOUT_DEPTH_READ_ONLY_OPTIMAL};
  for (uint32_t frame = 0; frame < kFrames; ++frame) {
    const uint32_t s = frame % kFramesInFlight;
    FrameSlot& slot = slots[s];
    if (vkWaitForFences(e.device, 1, &slot.fence, VK_TRUE, 10'000'000'000ull) != VK_SUCCESS)
      return fail("wait");
    vkResetFences(e.device, 1, &slot.fence);
    status = water->begin_frame(s);  // the slot's staging is free again: the GPU is done with it
    if (!status.ok()) return fail(status.message().c_str());

    siviflow::Camera camera;  // gliding down the river, 2 m a frame
    camera.position = {0.0f, 10.0f, -30.0f + 2.0f * frame};
    camera.target = {6.0f, 0.0f, 2.0f * frame};
    const double seconds = frame / 30.0;
    status = water->update(siviflow::camera_view(camera, kExtent), seconds);  // CPU only
    if (!status.ok()) return fail(status.message().c_str());

    vkResetCommandBuffer(slot.cmd, 0);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(slot.cmd, &begin);
    record_world(slot.cmd, slot);
    siviflow::FrameInputs inputs;  // each image: its state now, and the state to leave it in
    inputs.color = {slot.color, slot.color_view, kColorFormat, kExtent,
                    cleared,    copy_source,     kColorUsage};
    inputs.depth = {slot.depth, slot.depth_view, kDepthFormat, kExtent,
                    cleared,    depth_sampled,   kDepthUsage};
    inputs.readback[siviflow::ReadbackImage::kColor] = slot.readback;
    status = water->record(slot.cmd, inputs);
    if (!status.ok()) return fail(status.message().c_str());
    vkEndCommandBuffer(slot.cmd);
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &slot.cmd;
    if (vkQueueSubmit(e.queue, 1, &submit, slot.fence) != VK_SUCCESS) return fail("submit");
  }

  // The last frame of each slot: water on part of it, the engine's sky everywhere else.
  bool every_frame_shows_both = true;
  for (const FrameSlot& slot : slots) {
    if (vkWaitForFences(e.device, 1, &slot.fence, VK_TRUE, 10'000'000'000ull) != VK_SUCCESS)
      return fail("wait");
    unsigned sky_texels = 0, water_texels = 0;
    count_texels(e, slot, bytes, &sky_texels, &water_texels);
    std::printf("water texels %u, sky texels %u\n", water_texels, sky_texels);
    every_frame_shows_both = every_frame_shows_both && water_texels > 100 && sky_texels > 100;
  }
  water.reset();
  std::printf("%u frames, %u in flight, validation %s, errors %u\n", kFrames, kFramesInFlight,
              validate ? "on" : "not installed", g_validation_errors);
  return every_frame_shows_both && g_validation_errors == 0 ? 0 : 1;
}
