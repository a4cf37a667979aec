#include "view/swapchain.h"

#include <algorithm>

#include "vk/vk_text.h"

namespace siviflow::view {
namespace {

// The frame is copied in (transfer), the panel drawn over it, and a screenshot copied out.
constexpr VkImageUsageFlags kImageUsage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT |
                                          VK_IMAGE_USAGE_TRANSFER_DST_BIT |
                                          VK_IMAGE_USAGE_TRANSFER_SRC_BIT;

VkSurfaceFormatKHR pick_format(const std::vector<VkSurfaceFormatKHR>& formats) {
  // sRGB, so the blit from the linear frame encodes it as the capture's PNGs are.
  for (VkFormat wanted : {VK_FORMAT_B8G8R8A8_SRGB, VK_FORMAT_R8G8B8A8_SRGB}) {
    for (const VkSurfaceFormatKHR& f : formats) {
      if (f.format == wanted && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) return f;
    }
  }
  return formats.front();
}

}  // namespace

Status Swapchain::init(WindowDevice& device, bool no_vsync) {
  device_ = &device;
  uint32_t count = 0;
  vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device, device.surface, &count, nullptr);
  if (count == 0) return Status::error("the window's surface offers no format");
  std::vector<VkSurfaceFormatKHR> formats(count);
  vkGetPhysicalDeviceSurfaceFormatsKHR(device.physical_device, device.surface, &count,
                                       formats.data());
  format_ = pick_format(formats);

  vkGetPhysicalDeviceSurfacePresentModesKHR(device.physical_device, device.surface, &count,
                                            nullptr);
  std::vector<VkPresentModeKHR> modes(count);
  vkGetPhysicalDeviceSurfacePresentModesKHR(device.physical_device, device.surface, &count,
                                            modes.data());
  present_mode_ = VK_PRESENT_MODE_FIFO_KHR;  // always offered
  if (no_vsync) {
    for (VkPresentModeKHR wanted : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR}) {
      if (std::find(modes.begin(), modes.end(), wanted) != modes.end()) {
        present_mode_ = wanted;
        break;
      }
    }
  }

  VkAttachmentDescription color{};
  color.format = format_.format;
  color.samples = VK_SAMPLE_COUNT_1_BIT;
  color.loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;  // the frame copied in
  color.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  color.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  color.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  color.initialLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
  color.finalLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;  // the frame's barriers move it on
  VkAttachmentReference reference{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &reference;
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 1;
  info.pAttachments = &color;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  const VkResult result = vkCreateRenderPass(device.device, &info, nullptr, &overlay_pass_);
  if (result != VK_SUCCESS) return vk_failure("vkCreateRenderPass", result);
  return Status::success();
}

Status Swapchain::recreate(bool* minimised) {
  WindowDevice& d = *device_;
  VkSurfaceCapabilitiesKHR caps;
  VkResult result =
      vkGetPhysicalDeviceSurfaceCapabilitiesKHR(d.physical_device, d.surface, &caps);
  if (result != VK_SUCCESS) return vk_failure("vkGetPhysicalDeviceSurfaceCapabilitiesKHR", result);
  int width = 0;
  int height = 0;
  glfwGetFramebufferSize(d.window, &width, &height);
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == UINT32_MAX) {  // the window system lets the swapchain decide
    extent.width = std::clamp(static_cast<uint32_t>(width), caps.minImageExtent.width,
                              caps.maxImageExtent.width);
    extent.height = std::clamp(static_cast<uint32_t>(height), caps.minImageExtent.height,
                               caps.maxImageExtent.height);
  }
  *minimised = extent.width == 0 || extent.height == 0;
  if (*minimised) return Status::success();
  if ((caps.supportedUsageFlags & kImageUsage) != kImageUsage) {
    return Status::error("the window's swapchain images do not offer " +
                         image_usage_text(kImageUsage & ~caps.supportedUsageFlags) +
                         " (the frame is copied in, the panel drawn over it, a screenshot copied "
                         "out)");
  }

  min_image_count_ = std::max(caps.minImageCount, 2u);
  uint32_t image_count = caps.minImageCount + 1;
  if (caps.maxImageCount != 0) image_count = std::min(image_count, caps.maxImageCount);
  VkSwapchainCreateInfoKHR info{VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  info.surface = d.surface;
  info.minImageCount = image_count;
  info.imageFormat = format_.format;
  info.imageColorSpace = format_.colorSpace;
  info.imageExtent = extent;
  info.imageArrayLayers = 1;
  info.imageUsage = kImageUsage;
  info.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.preTransform = caps.currentTransform;
  info.compositeAlpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  info.presentMode = present_mode_;
  info.clipped = VK_TRUE;
  info.oldSwapchain = swapchain_;
  VkSwapchainKHR created = VK_NULL_HANDLE;
  result = vkCreateSwapchainKHR(d.device, &info, nullptr, &created);
  destroy_images();
  if (swapchain_ != VK_NULL_HANDLE) vkDestroySwapchainKHR(d.device, swapchain_, nullptr);
  swapchain_ = created;
  if (result != VK_SUCCESS) return vk_failure("vkCreateSwapchainKHR", result);
  extent_ = extent;

  vkGetSwapchainImagesKHR(d.device, swapchain_, &image_count, nullptr);
  images_.resize(image_count);
  vkGetSwapchainImagesKHR(d.device, swapchain_, &image_count, images_.data());
  for (VkImage image : images_) {
    VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view_info.image = image;
    view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view_info.format = format_.format;
    view_info.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    VkImageView view = VK_NULL_HANDLE;
    result = vkCreateImageView(d.device, &view_info, nullptr, &view);
    if (result != VK_SUCCESS) return vk_failure("vkCreateImageView", result);
    views_.push_back(view);
    VkFramebufferCreateInfo fb_info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb_info.renderPass = overlay_pass_;
    fb_info.attachmentCount = 1;
    fb_info.pAttachments = &view;
    fb_info.width = extent.width;
    fb_info.height = extent.height;
    fb_info.layers = 1;
    VkFramebuffer framebuffer = VK_NULL_HANDLE;
    result = vkCreateFramebuffer(d.device, &fb_info, nullptr, &framebuffer);
    if (result != VK_SUCCESS) return vk_failure("vkCreateFramebuffer", result);
    framebuffers_.push_back(framebuffer);
    VkSemaphoreCreateInfo semaphore_info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore semaphore = VK_NULL_HANDLE;
    result = vkCreateSemaphore(d.device, &semaphore_info, nullptr, &semaphore);
    if (result != VK_SUCCESS) return vk_failure("vkCreateSemaphore", result);
    present_semaphores_.push_back(semaphore);
  }
  return Status::success();
}

void Swapchain::destroy_images() {
  if (device_ == nullptr) return;
  const VkDevice device = device_->device;
  for (VkFramebuffer framebuffer : framebuffers_) vkDestroyFramebuffer(device, framebuffer, nullptr);
  for (VkImageView view : views_) vkDestroyImageView(device, view, nullptr);
  for (VkSemaphore semaphore : present_semaphores_) vkDestroySemaphore(device, semaphore, nullptr);
  framebuffers_.clear();
  views_.clear();
  present_semaphores_.clear();
  images_.clear();
}

void Swapchain::destroy() {
  if (device_ == nullptr) return;
  destroy_images();
  if (swapchain_ != VK_NULL_HANDLE) vkDestroySwapchainKHR(device_->device, swapchain_, nullptr);
  if (overlay_pass_ != VK_NULL_HANDLE) vkDestroyRenderPass(device_->device, overlay_pass_, nullptr);
  swapchain_ = VK_NULL_HANDLE;
  overlay_pass_ = VK_NULL_HANDLE;
}

}  // namespace siviflow::view
