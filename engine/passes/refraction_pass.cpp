#include "passes/passes.h"

#include "vk/device_table.h"

namespace siviflow {

DataHandle<VkOffset2D> add_refraction_copy_pass(FrameGraph& graph, ImageHandle color,
                                                ImageHandle* copy) {
  const auto viewport_offset = graph.declare_data<VkOffset2D>("refraction copy offset");
  PassBuilder pass = graph.add_pass("refraction copy", PassKind::Transfer);
  pass.transfer_read(color);
  *copy = pass.transfer_write(*copy);
  const ImageHandle source = color;
  const ImageHandle target = *copy;
  pass.record([viewport_offset, source, target](const PassContext& ctx) {
    const VkExtent2D extent = ctx.extent(target);
    VkImageCopy region{};
    region.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.srcOffset = {ctx.data(viewport_offset).x, ctx.data(viewport_offset).y, 0};
    region.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    region.extent = {extent.width, extent.height, 1};
    ctx.table().vkCmdCopyImage(ctx.cmd(), ctx.image(source), ctx.layout(source), ctx.image(target),
                               ctx.layout(target), 1, &region);
    return Status::success();
  });
  return viewport_offset;
}

}  // namespace siviflow
