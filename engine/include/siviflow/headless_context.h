// A small standalone Vulkan host: instance, device and one queue on any Vulkan 1.3 device, with
// no window. The capture tool and the tests use it to play the part an embedding engine plays;
// the renderer itself never creates a device (see renderer.h).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <vulkan/vulkan.h>

#include "siviflow/renderer.h"
#include "siviflow/status.h"
#include "siviflow/world.h"

namespace siviflow {

struct HeadlessContextOptions {
  // Enable VK_LAYER_KHRONOS_validation with synchronization validation and count its errors.
  bool enable_validation = false;
  // With enable_validation: a missing layer is an error instead of running without it.
  bool require_validation = false;
  // Refuse any device that is not Mesa lavapipe (driverID MESA_LLVMPIPE). Tests set it.
  bool require_lavapipe = false;
  // Print validation messages of warning severity and above to stderr as they arrive.
  bool print_validation_messages = true;
};

struct DeviceReport {
  std::string device_name;
  std::string driver_name;
  std::string driver_info;
  VkDriverId driver_id = VK_DRIVER_ID_MAX_ENUM;
  VkPhysicalDeviceType device_type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  uint32_t api_version = 0;
  uint32_t max_image_dimension_2d = 0;
  bool validation_layer_available = false;
  bool validation_enabled = false;
};

// An image or buffer the standalone host owns (destroyed with the context), as an embedding
// engine would own its render targets and readback buffers.
struct HostImage {
  VkImage image = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkImageUsageFlags usage = 0;  // what it was created with
};
struct HostBuffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  const void* data = nullptr;  // persistently mapped, host-coherent
};

class HeadlessContext {
 public:
  // Loads the Vulkan loader (libvulkan.so.1) at run time, creates the instance (with the
  // validation layer when asked), picks the first device that supports every required feature
  // and creates it with them enabled. Errors name what is missing.
  static Status create(const HeadlessContextOptions& options, std::unique_ptr<HeadlessContext>* out);
  ~HeadlessContext();
  HeadlessContext(const HeadlessContext&) = delete;
  HeadlessContext& operator=(const HeadlessContext&) = delete;

  VkInstance instance() const;
  VkPhysicalDevice physical_device() const;
  VkDevice device() const;
  VkQueue queue() const;
  uint32_t queue_family_index() const;
  PFN_vkGetInstanceProcAddr get_instance_proc_addr() const;
  PFN_vkGetDeviceProcAddr get_device_proc_addr() const;
  const DeviceReport& report() const;
  // A renderer CreateInfo for this device, with every handle, the enabled features and debug
  // labels (when validation is on) filled; the caller sets the rest.
  CreateInfo renderer_create_info(VkExtent2D extent, VkFormat color_format) const;
  // The same for the built-in world (siviflow/world.h).
  WorldCreateInfo world_create_info(VkFormat color_format, VkFormat depth_format) const;

  // One command buffer and fence per frame slot, as a host keeping frames in flight has.
  // begin_slot waits (bounded) for the slot's previous submission, then begins recording.
  Status begin_slot(uint32_t slot, VkCommandBuffer* cmd);
  Status end_slot_and_submit(uint32_t slot);
  Status wait_slot(uint32_t slot);
  Status wait_idle();

  // A colour image usable as a render target and as a copy source.
  Status create_target_image(VkFormat format, VkExtent2D extent, HostImage* out);
  // A depth image usable as a depth attachment, sampled and as a copy source.
  Status create_depth_image(VkFormat format, VkExtent2D extent, HostImage* out);
  // A host-visible buffer the GPU can copy into, mapped for reading.
  Status create_readback_buffer(VkDeviceSize size, HostBuffer* out);

  // Validation messages of error severity seen since creation (counts saturate per message id
  // in the layer, but any non-zero count means failure).
  uint32_t validation_error_count() const;
  std::vector<std::string> validation_errors() const;

 private:
  struct Impl;
  explicit HeadlessContext(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

// Whether the Khronos validation layer is installed, without creating an instance.
// Returns false when the Vulkan loader itself cannot be loaded.
bool validation_layer_present();

}  // namespace siviflow
