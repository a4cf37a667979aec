// The viewer's frames in flight, as an engine keeps them: per slot a command buffer, a fence, an
// acquire semaphore, timestamp queries, and the colour and depth images the world and the water
// are drawn into before the frame is copied to the swapchain image.
#pragma once

#include <cstdint>
#include <vector>

#include "siviflow/renderer.h"
#include "view/window_device.h"

namespace siviflow::view {

inline constexpr VkFormat kFrameColorFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
inline constexpr VkFormat kFrameDepthFormat = VK_FORMAT_D32_SFLOAT;

// Timestamps written per frame: start, after the world, after the water, after the overlay.
enum FrameTimestamp : uint32_t { kFrameStart, kAfterWorld, kAfterWater, kAfterOverlay, kTimestampCount };

struct FrameSlot {
  VkCommandPool pool = VK_NULL_HANDLE;
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
  VkSemaphore acquired = VK_NULL_HANDLE;
  VkQueryPool timestamps = VK_NULL_HANDLE;
  bool timestamps_written = false;
  ExternalImage color;  // states: where the last frame left them
  ExternalImage depth;
  VkDeviceMemory color_memory = VK_NULL_HANDLE;
  VkDeviceMemory depth_memory = VK_NULL_HANDLE;
};

class FrameSlots {
 public:
  Status create(WindowDevice& device, uint32_t count, VkExtent2D extent);
  // New colour and depth images at `extent`; the caller has waited idle.
  Status resize(VkExtent2D extent);
  void destroy();

  uint32_t count() const { return static_cast<uint32_t>(slots_.size()); }
  FrameSlot& operator[](uint32_t i) { return slots_[i]; }
  // Milliseconds between the slot's timestamps `from` and `to` of its last finished frame.
  double gpu_ms(uint32_t slot, FrameTimestamp from, FrameTimestamp to) const;
  void read_timestamps(uint32_t slot);

 private:
  Status create_images(FrameSlot* slot, VkExtent2D extent);
  void destroy_images(FrameSlot* slot);
  Status create_image(VkFormat format, VkExtent2D extent, VkImageUsageFlags usage,
                      VkImageAspectFlags aspect, ExternalImage* out, VkDeviceMemory* memory);

  WindowDevice* device_ = nullptr;
  std::vector<FrameSlot> slots_;
  std::vector<std::vector<uint64_t>> ticks_;  // per slot, the last read timestamps
  double ns_per_tick_ = 1.0;
};

}  // namespace siviflow::view
