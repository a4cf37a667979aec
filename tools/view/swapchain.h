// The viewer's swapchain: images, their views and framebuffers for the overlay render pass (the
// panel, drawn over the frame after it is copied in), and a present semaphore per image.
// Recreated whole on resize, minimise and out-of-date.
#pragma once

#include <cstdint>
#include <vector>

#include "view/window_device.h"

namespace siviflow::view {

class Swapchain {
 public:
  // Picks an sRGB BGRA/RGBA format and the present mode (FIFO, or with `no_vsync` MAILBOX then
  // IMMEDIATE where offered) and creates the overlay render pass for it.
  Status init(WindowDevice& device, bool no_vsync);
  // (Re)creates the swapchain at the window's framebuffer size; the caller has waited idle.
  // `*minimised` is set when the window has no area (nothing is created then).
  Status recreate(bool* minimised);
  void destroy();

  VkSwapchainKHR swapchain() const { return swapchain_; }
  VkFormat format() const { return format_.format; }
  VkExtent2D extent() const { return extent_; }
  VkPresentModeKHR present_mode() const { return present_mode_; }
  VkRenderPass overlay_pass() const { return overlay_pass_; }
  uint32_t image_count() const { return static_cast<uint32_t>(images_.size()); }
  uint32_t min_image_count() const { return min_image_count_; }
  VkImage image(uint32_t i) const { return images_[i]; }
  VkFramebuffer framebuffer(uint32_t i) const { return framebuffers_[i]; }
  // Signalled by the frame's submit, waited on by its present: one per image, since an image's
  // next acquire proves its previous present finished with the semaphore.
  VkSemaphore present_semaphore(uint32_t i) const { return present_semaphores_[i]; }

 private:
  void destroy_images();

  WindowDevice* device_ = nullptr;
  VkSurfaceFormatKHR format_{};
  VkPresentModeKHR present_mode_ = VK_PRESENT_MODE_FIFO_KHR;
  uint32_t min_image_count_ = 2;
  VkRenderPass overlay_pass_ = VK_NULL_HANDLE;
  VkSwapchainKHR swapchain_ = VK_NULL_HANDLE;
  VkExtent2D extent_{0, 0};
  std::vector<VkImage> images_;
  std::vector<VkImageView> views_;
  std::vector<VkFramebuffer> framebuffers_;
  std::vector<VkSemaphore> present_semaphores_;
};

}  // namespace siviflow::view
