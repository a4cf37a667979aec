// `--screenshot`: the last presented swapchain image copied into a host buffer in the same
// command buffer, then written as PNG (atomically) once its frame has finished.
#pragma once

#include <string>

#include "siviflow/renderer.h"
#include "view/window_device.h"

namespace siviflow::view {

class Screenshot {
 public:
  // The state the image is left in by record_copy().
  static constexpr ImageState kCopySource = {VK_PIPELINE_STAGE_2_COPY_BIT,
                                             VK_ACCESS_2_TRANSFER_READ_BIT,
                                             VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL};
  // Records the copy of `image` (in state `from`, `extent` texels of 4 bytes) into the buffer.
  Status record_copy(WindowDevice& device, VkCommandBuffer cmd, VkImage image,
                     const ImageState& from, VkExtent2D extent);
  // Writes what the last copy holds, its frame finished, as PNG; `format` is the image's.
  Status write_png(const std::string& path, VkFormat format) const;
  void destroy();

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  void* mapped_ = nullptr;
  VkExtent2D extent_{0, 0};
};

}  // namespace siviflow::view
