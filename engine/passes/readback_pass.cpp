#include "passes/passes.h"

#include "vk/device_table.h"

namespace siviflow {

void add_readback_pass(FrameGraph& graph, ReadbackHandles* handles) {
  PassBuilder pass = graph.add_pass("readback", PassKind::Transfer);
  pass.transfer_read(handles->color);
  pass.transfer_read(handles->depth);
  handles->color_buffer = pass.transfer_write(handles->color_buffer);
  handles->depth_buffer = pass.transfer_write(handles->depth_buffer);
  pass.side_effect();
  const ReadbackHandles h = *handles;
  pass.record([h](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    const VkExtent2D extent = ctx.extent(h.color);
    VkBufferImageCopy region{};
    region.bufferOffset = ctx.offset(h.color_buffer);
    region.imageExtent = {extent.width, extent.height, 1};  // tightly packed rows
    region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    vk.vkCmdCopyImageToBuffer(ctx.cmd(), ctx.image(h.color), ctx.layout(h.color),
                              ctx.buffer(h.color_buffer), 1, &region);
    region.bufferOffset = ctx.offset(h.depth_buffer);
    region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
    vk.vkCmdCopyImageToBuffer(ctx.cmd(), ctx.image(h.depth), ctx.layout(h.depth),
                              ctx.buffer(h.depth_buffer), 1, &region);
    return Status::success();
  });
}

}  // namespace siviflow
