#include "passes/passes.h"

#include "vk/device_table.h"

namespace siviflow {

DataHandle<std::vector<ReadbackCopy>> add_readback_pass(FrameGraph& graph,
                                                        std::vector<ReadbackCopy>* copies) {
  const auto frame_copies = graph.declare_data<std::vector<ReadbackCopy>>("readback copies");
  PassBuilder pass = graph.add_pass("readback", PassKind::Transfer);
  for (ReadbackCopy& copy : *copies) {
    pass.transfer_read(copy.image);
    copy.buffer = pass.transfer_write(copy.buffer);
  }
  pass.side_effect();
  pass.record([frame_copies](const PassContext& ctx) {
    const DeviceTable& vk = ctx.table();
    for (const ReadbackCopy& copy : ctx.data(frame_copies)) {
      const bool whole = copy.region.extent.width == 0 || copy.region.extent.height == 0;
      const VkExtent2D extent = whole ? ctx.extent(copy.image) : copy.region.extent;
      VkBufferImageCopy region{};
      region.bufferOffset = ctx.offset(copy.buffer);
      region.imageOffset = {whole ? 0 : copy.region.offset.x, whole ? 0 : copy.region.offset.y, 0};
      region.imageExtent = {extent.width, extent.height, 1};  // tightly packed rows
      // A depth/stencil image is read through its depth aspect only.
      const VkImageAspectFlags aspect = aspect_of(ctx.format(copy.image));
      region.imageSubresource = {(aspect & VK_IMAGE_ASPECT_DEPTH_BIT) != 0
                                     ? VkImageAspectFlags{VK_IMAGE_ASPECT_DEPTH_BIT}
                                     : aspect,
                                 0, 0, 1};
      vk.vkCmdCopyImageToBuffer(ctx.cmd(), ctx.image(copy.image), ctx.layout(copy.image),
                                ctx.buffer(copy.buffer), 1, &region);
    }
    return Status::success();
  });
  return frame_copies;
}

}  // namespace siviflow
