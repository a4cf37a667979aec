// A modern engine's frame around an installed SiViFlow, built as C++17 against siviflow::water
// alone: an HDR colour target (B10G11R11_UFLOAT_PACK32), a reverse-Z projection with an infinite
// far plane and a Halton(2,3) jitter, motion vectors (R16G16_SFLOAT) and a reactive mask
// (R8_UNORM) for its temporal filter, the water's depth written back, and a camera that moves
// and turns between frames. The river is the engine's own: a straight, level channel whose
// surface is the plane y = 0, so every check has an analytic answer. Exits 0 only when
//   - on the water, the motion vectors match the reprojection of the surface point through the
//     unjittered matrices of this frame and the last (median error <= 0.05 px, 99th percentile
//     <= 0.5 px), zero on the first frame and after a camera cut, and the written depth is the
//     surface's;
//   - the reactive mask is above 0 on the water;
//   - off the water, the engine's motion, reactive and depth values are untouched;
//   - the validation layer, with synchronization validation, reported nothing.
#include <siviflow/renderer.h>
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/packing.hpp>
#include <glm/mat4x4.hpp>
#include <memory>
#include <vector>

namespace {

constexpr VkExtent2D kExtent{640, 360};
constexpr VkFormat kColorFormat = VK_FORMAT_B10G11R11_UFLOAT_PACK32;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
constexpr VkFormat kMotionFormat = VK_FORMAT_R16G16_SFLOAT;
constexpr VkFormat kReactiveFormat = VK_FORMAT_R8_UNORM;
constexpr float kNear = 0.1f;
constexpr uint32_t kFrames = 6;
constexpr uint32_t kCutFrame = 3;  // View::camera_cut: motion zero, as on the first frame
// What the engine's own passes left in its images before the water: a sky, the far plane
// (0 under reverse-Z), a motion and a reactive value of its own, each exact in its format.
constexpr float kSky[4] = {0.45f, 0.6f, 0.8f, 1.0f};
constexpr float kHostMotion[2] = {0.25f, -0.125f};
constexpr uint8_t kHostReactive = 51;
// The channel: x in [-kHalfWidth, kHalfWidth], z in [0, kLength], surface y = 0.
constexpr float kHalfWidth = 12.0f;
constexpr float kLength = 400.0f;
constexpr VkImageUsageFlags kTargetUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                           VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                           VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
constexpr VkImageUsageFlags kDepthUsage =
    VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_SAMPLED_BIT |
    VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;

unsigned g_validation_messages = 0;

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  if (severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                  VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT)) {
    ++g_validation_messages;
    std::fprintf(stderr, "validation: %s\n", data->pMessage);
  }
  return VK_FALSE;
}

int fail(const char* what) {
  std::fprintf(stderr, "modern_frame: %s\n", what);
  return 1;
}

uint32_t memory_type(VkPhysicalDevice gpu, uint32_t bits, VkMemoryPropertyFlags wanted) {
  VkPhysicalDeviceMemoryProperties props;
  vkGetPhysicalDeviceMemoryProperties(gpu, &props);
  for (uint32_t i = 0; i < props.memoryTypeCount; ++i) {
    if ((bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & wanted) == wanted) return i;
  }
  return UINT32_MAX;
}

struct Target {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkFormat format = VK_FORMAT_UNDEFINED;
  VkImageUsageFlags usage = 0;
  VkImageAspectFlags aspect = 0;
  uint32_t texel_bytes = 0;
  VkBuffer readback = VK_NULL_HANDLE;
  void* mapped = nullptr;
};

struct Engine {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice gpu = VK_NULL_HANDLE;
  uint32_t family = 0;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::vector<Target> targets;
  std::vector<VkDeviceMemory> memories;
  VkCommandPool pool = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;

  ~Engine() {
    if (device != VK_NULL_HANDLE) {
      vkDeviceWaitIdle(device);
      vkDestroyFence(device, fence, nullptr);
      vkDestroyCommandPool(device, pool, nullptr);
      for (const Target& t : targets) {
        vkDestroyBuffer(device, t.readback, nullptr);
        vkDestroyImageView(device, t.view, nullptr);
        vkDestroyImage(device, t.image, nullptr);
      }
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

  // An image of the frame's size and a host-visible buffer it is copied into after the frame.
  bool target(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect,
              uint32_t texel_bytes, Target* out) {
    out->format = format;
    out->usage = usage;
    out->aspect = aspect;
    out->texel_bytes = texel_bytes;
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {kExtent.width, kExtent.height, 1};
    info.mipLevels = 1;
    info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.usage = usage;
    if (vkCreateImage(device, &info, nullptr, &out->image) != VK_SUCCESS) return false;
    VkMemoryRequirements needs;
    vkGetImageMemoryRequirements(device, out->image, &needs);
    VkDeviceMemory memory = VK_NULL_HANDLE;
    if (!bind(needs, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, &memory)) return false;
    vkBindImageMemory(device, out->image, memory, 0);
    VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view_info.image = out->image;
    view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view_info.format = format;
    view_info.subresourceRange = {aspect, 0, 1, 0, 1};
    if (vkCreateImageView(device, &view_info, nullptr, &out->view) != VK_SUCCESS) return false;
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = VkDeviceSize{kExtent.width} * kExtent.height * texel_bytes;
    buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
    if (vkCreateBuffer(device, &buffer_info, nullptr, &out->readback) != VK_SUCCESS) return false;
    vkGetBufferMemoryRequirements(device, out->readback, &needs);
    if (!bind(needs, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT,
              &memory)) {
      return false;
    }
    vkBindBufferMemory(device, out->readback, memory, 0);
    return vkMapMemory(device, memory, 0, VK_WHOLE_SIZE, 0, &out->mapped) == VK_SUCCESS;
  }
};

bool create_engine(Engine* e, siviflow::RequiredDeviceFeatures* required) {
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const char* debug_utils = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  const VkValidationFeatureEnableEXT sync =
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &sync;
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "modern_frame";
  app.apiVersion = VK_API_VERSION_1_3;
  VkInstanceCreateInfo instance_info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  instance_info.pNext = &features;
  instance_info.pApplicationInfo = &app;
  instance_info.enabledLayerCount = 1;
  instance_info.ppEnabledLayerNames = &layer;
  instance_info.enabledExtensionCount = 1;
  instance_info.ppEnabledExtensionNames = &debug_utils;
  if (vkCreateInstance(&instance_info, nullptr, &e->instance) != VK_SUCCESS) return false;
  VkDebugUtilsMessengerCreateInfoEXT messenger{
      VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                              VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  messenger.pfnUserCallback = &on_message;
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(e->instance, "vkCreateDebugUtilsMessengerEXT"));
  if (create == nullptr || create(e->instance, &messenger, nullptr, &e->messenger) != VK_SUCCESS) {
    return false;
  }
  uint32_t count = 0;
  vkEnumeratePhysicalDevices(e->instance, &count, nullptr);
  std::vector<VkPhysicalDevice> gpus(count);
  vkEnumeratePhysicalDevices(e->instance, &count, gpus.data());
  *required = siviflow::required_device_features();
  required->link();
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
    for (uint32_t f = 0; f < families && e->gpu == VK_NULL_HANDLE; ++f) {
      if (props[f].queueFlags & VK_QUEUE_GRAPHICS_BIT) {
        e->gpu = gpu;
        e->family = f;
      }
    }
    if (e->gpu != VK_NULL_HANDLE) break;
  }
  if (e->gpu == VK_NULL_HANDLE) return false;
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = e->family;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  device_info.pNext = &required->features2;
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  if (vkCreateDevice(e->gpu, &device_info, nullptr, &e->device) != VK_SUCCESS) return false;
  vkGetDeviceQueue(e->device, e->family, 0, &e->queue);
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = e->family;
  if (vkCreateCommandPool(e->device, &pool_info, nullptr, &e->pool) != VK_SUCCESS) return false;
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  return vkCreateFence(e->device, &fence_info, nullptr, &e->fence) == VK_SUCCESS;
}

// The engine's river: a level channel of 4 m sections, 7 vertices across, 2 m deep.
struct Channel {
  std::vector<glm::vec3> positions;
  std::vector<uint32_t> indices;
  std::vector<float> depth;
  std::vector<float> slope;
};

Channel make_channel() {
  Channel c;
  constexpr uint32_t kAcross = 7;
  constexpr uint32_t kSections = 101;
  for (uint32_t s = 0; s < kSections; ++s) {
    for (uint32_t i = 0; i < kAcross; ++i) {
      const float x = -kHalfWidth + 2.0f * kHalfWidth * static_cast<float>(i) / (kAcross - 1);
      c.positions.push_back({x, 0.0f, kLength * static_cast<float>(s) / (kSections - 1)});
      c.depth.push_back(2.0f);
      c.slope.push_back(0.001f);
    }
  }
  for (uint32_t s = 0; s + 1 < kSections; ++s) {
    for (uint32_t i = 0; i + 1 < kAcross; ++i) {
      const uint32_t a = s * kAcross + i;
      const uint32_t b = a + kAcross;
      const uint32_t quad[6] = {a, b, a + 1, a + 1, b, b + 1};
      c.indices.insert(c.indices.end(), quad, quad + 6);
    }
  }
  return c;
}

// Halton(2,3), centred: the sub-pixel jitter of frame n.
float halton(uint32_t index, uint32_t base) {
  float result = 0.0f;
  float fraction = 1.0f / static_cast<float>(base);
  for (uint32_t i = index + 1; i > 0; i /= base) {
    result += fraction * static_cast<float>(i % base);
    fraction /= static_cast<float>(base);
  }
  return result;
}

// Reverse-Z, infinite far plane, Vulkan clip space (y down): depth = near / view distance.
glm::mat4 reverse_z_infinite(float fov_y, float aspect) {
  const float f = 1.0f / std::tan(0.5f * fov_y);
  glm::mat4 p(0.0f);
  p[0][0] = f / aspect;
  p[1][1] = -f;
  p[2][3] = -1.0f;
  p[3][2] = kNear;
  return p;
}

// The camera of frame n: flying down the channel, turning a little.
glm::mat4 camera_at(uint32_t frame) {
  const float t = static_cast<float>(frame);
  const glm::vec3 eye(1.0f + 0.4f * t, 9.0f + 0.3f * t, -25.0f + 2.0f * t);
  const glm::vec3 target(3.0f - 1.5f * t, 0.0f, 60.0f + 2.0f * t);
  return glm::lookAtRH(eye, target, glm::vec3(0.0f, 1.0f, 0.0f));
}

// The surface point seen through pixel centre (x, y) under `view_proj` (with its jitter), or
// false where the ray does not meet the channel well inside its banks.
bool surface_point(const glm::mat4& view_proj, float x, float y, glm::vec3* out) {
  const glm::mat4 inverse = glm::inverse(view_proj);
  const glm::vec2 ndc(2.0f * x / kExtent.width - 1.0f, 2.0f * y / kExtent.height - 1.0f);
  const glm::vec4 near_h = inverse * glm::vec4(ndc, 1.0f, 1.0f);
  const glm::vec4 far_h = inverse * glm::vec4(ndc, 0.5f, 1.0f);
  const glm::vec3 a = glm::vec3(near_h) / near_h.w;
  const glm::vec3 b = glm::vec3(far_h) / far_h.w;
  const glm::vec3 d = b - a;
  if (!(d.y < 0.0f)) return false;  // looking up: no water
  const float s = -a.y / d.y;
  *out = a + s * d;
  return true;
}

enum class Place { kWater, kDry, kEdge };

// Well inside the channel, well outside it, or near a bank (where a pixel may go either way).
Place place_of(const glm::vec3& p, bool hit) {
  if (!hit) return Place::kDry;
  constexpr float kMargin = 0.5f;
  const bool inside =
      std::abs(p.x) < kHalfWidth - kMargin && p.z > kMargin && p.z < kLength - kMargin;
  const bool outside =
      std::abs(p.x) > kHalfWidth + kMargin || p.z < -kMargin || p.z > kLength + kMargin;
  return inside ? Place::kWater : outside ? Place::kDry : Place::kEdge;
}

glm::vec2 viewport_uv(const glm::mat4& view_proj, const glm::vec3& p) {
  const glm::vec4 clip = view_proj * glm::vec4(p, 1.0f);
  return 0.5f * glm::vec2(clip) / clip.w + 0.5f;
}

void barrier(VkCommandBuffer cmd, const Target& t, VkImageLayout from, VkImageLayout to,
             VkPipelineStageFlags2 src_stage, VkAccessFlags2 src_access,
             VkPipelineStageFlags2 dst_stage, VkAccessFlags2 dst_access) {
  VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
  b.srcStageMask = src_stage;
  b.srcAccessMask = src_access;
  b.dstStageMask = dst_stage;
  b.dstAccessMask = dst_access;
  b.oldLayout = from;
  b.newLayout = to;
  b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  b.image = t.image;
  b.subresourceRange = {t.aspect, 0, 1, 0, 1};
  VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
  dependency.imageMemoryBarrierCount = 1;
  dependency.pImageMemoryBarriers = &b;
  vkCmdPipelineBarrier2(cmd, &dependency);
}

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 1e9;
  std::sort(values.begin(), values.end());
  const size_t i = std::min(values.size() - 1, static_cast<size_t>(q * (values.size() - 1)));
  return values[i];
}

}  // namespace

int main() {
  Engine e;
  siviflow::RequiredDeviceFeatures required;
  if (!create_engine(&e, &required)) {
    return fail(
        "no Vulkan 1.3 instance with the Khronos validation layer and a device with "
        "SiViFlow's features");
  }
  Target color, depth, motion, reactive;
  if (!e.target(kColorFormat, kTargetUsage, VK_IMAGE_ASPECT_COLOR_BIT, 4, &color) ||
      !e.target(kDepthFormat, kDepthUsage, VK_IMAGE_ASPECT_DEPTH_BIT, 4, &depth) ||
      !e.target(kMotionFormat, kTargetUsage, VK_IMAGE_ASPECT_COLOR_BIT, 4, &motion) ||
      !e.target(kReactiveFormat, kTargetUsage, VK_IMAGE_ASPECT_COLOR_BIT, 1, &reactive)) {
    return fail("render targets");
  }
  e.targets = {color, depth, motion, reactive};

  const Channel channel = make_channel();
  siviflow::WaterRiver river;
  river.positions = channel.positions;
  river.indices = channel.indices;
  river.depth = channel.depth;
  river.slope = channel.slope;
  river.flow.discharge = 24.0f;
  siviflow::CreateInfo info;
  info.instance = e.instance;
  info.physical_device = e.gpu;
  info.device = e.device;
  info.get_instance_proc_addr = vkGetInstanceProcAddr;
  info.get_device_proc_addr = vkGetDeviceProcAddr;
  info.enabled_features = &required.features2;
  info.queue_family_index = e.family;
  info.frames_in_flight = 1;
  info.color_format = kColorFormat;
  info.depth_format = kDepthFormat;
  info.motion_format = kMotionFormat;
  info.reactive_format = kReactiveFormat;
  info.write_depth = true;
  info.extent = kExtent;
  info.river = &river;
  std::unique_ptr<siviflow::Renderer> water;
  siviflow::Status status = siviflow::Renderer::create(info, &water);
  if (!status.ok()) return fail(status.message().c_str());

  VkCommandBufferAllocateInfo cmd_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cmd_info.commandPool = e.pool;
  cmd_info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cmd_info.commandBufferCount = 1;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  if (vkAllocateCommandBuffers(e.device, &cmd_info, &cmd) != VK_SUCCESS) return fail("commands");

  const glm::mat4 projection =
      reverse_z_infinite(glm::radians(55.0f), static_cast<float>(kExtent.width) / kExtent.height);
  glm::mat4 previous_steady(1.0f);
  std::vector<double> errors;
  unsigned water_pixels = 0, reactive_zero = 0, touched_dry = 0, depth_wrong = 0;
  unsigned still_frames_moving = 0;
  for (uint32_t frame = 0; frame < kFrames; ++frame) {
    // The projection carries this frame's jitter: a point at pixel p lands at p + jitter.
    const glm::vec2 jitter(halton(frame, 2) - 0.5f, halton(frame, 3) - 0.5f);
    glm::mat4 jittered = projection;
    jittered[2][0] -= 2.0f * jitter.x / kExtent.width;
    jittered[2][1] -= 2.0f * jitter.y / kExtent.height;
    siviflow::View view;
    view.view = camera_at(frame);
    view.projection = jittered;
    view.jitter = jitter;
    view.camera_cut = frame == kCutFrame;  // as after a teleport: no history to move from
    if (!water->begin_frame(0).ok()) return fail("begin_frame");
    status = water->update(view, frame / 60.0);
    if (!status.ok()) return fail(status.message().c_str());

    // The engine's passes before the water: sky, far depth, its own motion and reactive values.
    vkResetCommandBuffer(cmd, 0);
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vkBeginCommandBuffer(cmd, &begin);
    for (const Target* t : {&color, &depth, &motion, &reactive}) {
      barrier(cmd, *t, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
              VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_CLEAR_BIT,
              VK_ACCESS_2_TRANSFER_WRITE_BIT);
    }
    const VkImageSubresourceRange color_range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    const VkImageSubresourceRange depth_range{VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
    VkClearColorValue value{};
    std::memcpy(value.float32, kSky, sizeof(kSky));
    vkCmdClearColorImage(cmd, color.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &value, 1,
                         &color_range);
    value = {};
    value.float32[0] = kHostMotion[0];
    value.float32[1] = kHostMotion[1];
    vkCmdClearColorImage(cmd, motion.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &value, 1,
                         &color_range);
    value = {};
    value.float32[0] = kHostReactive / 255.0f;
    vkCmdClearColorImage(cmd, reactive.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &value, 1,
                         &color_range);
    const VkClearDepthStencilValue far_plane{0.0f, 0};
    vkCmdClearDepthStencilImage(cmd, depth.image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &far_plane,
                                1, &depth_range);

    // The water, every image handed back ready to copy.
    const siviflow::ImageState cleared{VK_PIPELINE_STAGE_2_CLEAR_BIT,
                                       VK_ACCESS_2_TRANSFER_WRITE_BIT,
                                       VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL};
    const siviflow::ImageState to_copy{VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                                       VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
    siviflow::FrameInputs inputs;
    inputs.color = {color.image, color.view, kColorFormat, kExtent, cleared, to_copy, color.usage};
    inputs.depth = {depth.image, depth.view, kDepthFormat, kExtent, cleared, to_copy, depth.usage};
    inputs.motion = {motion.image, motion.view, kMotionFormat, kExtent,
                     cleared,      to_copy,     motion.usage};
    inputs.reactive = {reactive.image, reactive.view, kReactiveFormat, kExtent,
                       cleared,        to_copy,       reactive.usage};
    status = water->record(cmd, inputs);
    if (!status.ok()) return fail(status.message().c_str());
    for (const Target* t : {&color, &depth, &motion, &reactive}) {
      VkBufferImageCopy region{};
      region.imageSubresource = {t->aspect, 0, 0, 1};
      region.imageExtent = {kExtent.width, kExtent.height, 1};
      vkCmdCopyImageToBuffer(cmd, t->image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, t->readback, 1,
                             &region);
    }
    VkBufferMemoryBarrier2 to_host{VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER_2};
    to_host.srcStageMask = VK_PIPELINE_STAGE_2_COPY_BIT;
    to_host.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
    to_host.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
    to_host.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
    to_host.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    to_host.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    VkBufferMemoryBarrier2 buffers[4];
    const Target* all[4] = {&color, &depth, &motion, &reactive};
    for (int i = 0; i < 4; ++i) {
      buffers[i] = to_host;
      buffers[i].buffer = all[i]->readback;
      buffers[i].size = VK_WHOLE_SIZE;
    }
    VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dependency.bufferMemoryBarrierCount = 4;
    dependency.pBufferMemoryBarriers = buffers;
    vkCmdPipelineBarrier2(cmd, &dependency);
    vkEndCommandBuffer(cmd);
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cmd;
    vkResetFences(e.device, 1, &e.fence);
    if (vkQueueSubmit(e.queue, 1, &submit, e.fence) != VK_SUCCESS) return fail("submit");
    if (vkWaitForFences(e.device, 1, &e.fence, VK_TRUE, 30'000'000'000ull) != VK_SUCCESS) {
      return fail("wait");
    }

    // Every pixel against the analytic surface.
    const glm::mat4 steady = projection * view.view;
    const glm::mat4 drawn = jittered * view.view;
    const auto* motions = static_cast<const uint16_t*>(motion.mapped);
    const auto* reactives = static_cast<const uint8_t*>(reactive.mapped);
    const auto* depths = static_cast<const float*>(depth.mapped);
    for (uint32_t y = 0; y < kExtent.height; ++y) {
      for (uint32_t x = 0; x < kExtent.width; ++x) {
        const size_t i = size_t{y} * kExtent.width + x;
        glm::vec3 p;
        const bool hit = surface_point(drawn, x + 0.5f, y + 0.5f, &p);
        const Place place = place_of(p, hit);
        const glm::vec2 m(glm::unpackHalf1x16(motions[2 * i]),
                          glm::unpackHalf1x16(motions[2 * i + 1]));
        if (place == Place::kDry) {
          const bool kept = m.x == kHostMotion[0] && m.y == kHostMotion[1] &&
                            reactives[i] == kHostReactive && depths[i] == 0.0f;
          touched_dry += kept ? 0 : 1;
          continue;
        }
        if (place != Place::kWater) continue;
        ++water_pixels;
        reactive_zero += reactives[i] == 0 ? 1 : 0;
        const float view_distance = -(view.view * glm::vec4(p, 1.0f)).z;
        depth_wrong += std::abs(depths[i] - kNear / view_distance) > 1e-3f * kNear / view_distance;
        if (frame == 0 || frame == kCutFrame) {
          still_frames_moving += m == glm::vec2(0.0f) ? 0 : 1;
          continue;
        }
        const glm::vec2 expected = viewport_uv(previous_steady, p) - viewport_uv(steady, p);
        const glm::vec2 error = (m - expected) * glm::vec2(kExtent.width, kExtent.height);
        errors.push_back(glm::length(error));
      }
    }
    previous_steady = steady;
  }
  water.reset();

  const double median = percentile(errors, 0.5);
  const double p99 = percentile(errors, 0.99);
  std::printf(
      "water pixels %u, motion error median %.4f px, p99 %.4f px over %zu samples; "
      "reactive 0 on %u, depth wrong on %u, first and cut frames moving on %u, dry pixels "
      "touched %u, validation messages %u\n",
      water_pixels, median, p99, errors.size(), reactive_zero, depth_wrong, still_frames_moving,
      touched_dry, g_validation_messages);
  const bool ok = water_pixels > kFrames * kExtent.width * kExtent.height / 10 && median <= 0.05 &&
                  p99 <= 0.5 && reactive_zero == 0 && depth_wrong == 0 &&
                  still_frames_moving == 0 && touched_dry == 0 && g_validation_messages == 0;
  return ok ? 0 : 1;
}
